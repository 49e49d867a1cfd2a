"""MAVProxy, run non-interactively, fetches parameters, loads waypoints and arms."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from companion.failsafe import FAILSAFE_PARAMS
from companion.plugins.link.mavlink_link import MavlinkLink
from tests.protocol.mav_client import client_vehicle, free_udp_port
from tests.support.vehicle import wait_for

WAYPOINTS = """QGC WPL 110
0\t1\t0\t16\t0\t0\t0\t0\t-37.9105\t145.1340\t100\t1
1\t0\t3\t16\t0\t0\t0\t0\t-37.9100\t145.1340\t100\t1
2\t0\t3\t16\t0\t0\t0\t0\t-37.9100\t145.1350\t100\t1
"""


@pytest.mark.timeout(120)
def test_mavproxy_param_fetch_wp_load_and_arm(vehicle_factory, tmp_path):
    mavproxy = Path(sys.executable).parent / "mavproxy.py"
    assert mavproxy.exists() or shutil.which("mavproxy.py"), "MAVProxy is a dev dependency"
    port = free_udp_port()
    vehicle = vehicle_factory(client_vehicle(f"udpin://127.0.0.1:{port}", tmp_path / "state"))
    vehicle.wait_running("link")
    wp = tmp_path / "wp.txt"
    wp.write_text(WAYPOINTS)
    # MAVProxy's --cmd runs before it has heard the vehicle (and then resets its waypoint
    # loader when the vehicle comes online), so commands are typed once it is connected.
    proc = subprocess.Popen(
        [sys.executable, str(mavproxy), f"--master=udpout:127.0.0.1:{port}"],
        cwd=tmp_path,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    mission = tmp_path / "state" / "missions" / "mission.json"
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(proc.stdout), daemon=True)
    reader.start()
    try:
        wait_for(lambda: vehicle.row("link").frames_ok > 20, 30, "MAVProxy connected")
        time.sleep(2.0)
        for line in ("param fetch", f"wp load {wp}", "arm throttle"):
            proc.stdin.write(line + "\n")
            proc.stdin.flush()
        wait_for(lambda: vehicle.row("flight").pid, 30, "MAVProxy's arm to start the flight group")
        wait_for(mission.exists, 20, "the uploaded mission stored")
        # MAVProxy tries MAVLink FTP first (the vehicle does not offer it), then the protocol.
        # Every parameter the config's plug-ins declare: the link's rates, the failsafes.
        count = len(MavlinkLink.params) + len(FAILSAFE_PARAMS)
        said = f"Received {count} parameters"
        wait_for(lambda: any(said in x for x in lines), 30, "param fetch")
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()  # MAVProxy's own threads can ignore SIGTERM while stdin is open
            proc.wait(timeout=5)
        reader.join(timeout=5)
    output = "".join(lines)
    assert f"Received {len(MavlinkLink.params) + len(FAILSAFE_PARAMS)} parameters" in output
    assert "COMPONENT_ARM_DISARM: ACCEPTED" in output
    assert len(json.loads(mission.read_text())) == 3


@pytest.mark.timeout(120)
def test_mavproxy_switches_modes_auto_rtl_loiter(vehicle_factory, tmp_path):
    from companion.messages import FlightMode

    mavproxy = Path(sys.executable).parent / "mavproxy.py"
    port = free_udp_port()
    vehicle = vehicle_factory(client_vehicle(f"udpin://127.0.0.1:{port}", tmp_path / "state"))
    status = vehicle.bus.latest_reader("vehicle/status")
    wait_for(status.get, 20, "the commander up")
    wp = tmp_path / "wp.txt"
    wp.write_text(WAYPOINTS)
    proc = subprocess.Popen(
        [sys.executable, str(mavproxy), f"--master=udpout:127.0.0.1:{port}"],
        cwd=tmp_path,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(proc.stdout), daemon=True)
    reader.start()

    def type_line(line: str) -> None:
        proc.stdin.write(line + "\n")
        proc.stdin.flush()

    seen = []
    try:
        wait_for(lambda: vehicle.row("link").frames_ok > 20, 30, "MAVProxy connected")
        time.sleep(2.0)
        type_line(f"wp load {wp}")
        wait_for((tmp_path / "state" / "missions" / "mission.json").exists, 20, "mission stored")
        for command, mode in (
            ("mode AUTO", FlightMode.MISSION),
            ("mode RTL", FlightMode.RTL),
            ("mode LOITER", FlightMode.LOITER),
        ):
            type_line(command)
            wait_for(lambda m=mode: status.get().mode == m, 10, command)
            seen.append(FlightMode(status.get().mode))
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=5)
        reader.join(timeout=5)
    assert seen == [FlightMode.MISSION, FlightMode.RTL, FlightMode.LOITER]
