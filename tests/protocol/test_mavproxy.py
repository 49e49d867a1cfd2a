"""MAVProxy, run non-interactively, fetches parameters, loads waypoints and arms."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from companion.actuators.minissc import FrameDecoder
from companion.plugins.link.mavlink_link import MavlinkLink
from companion.plugins.vehicle.commander import CommanderPlugin
from tests.protocol.mav_client import free_udp_port
from tests.support.configs import client_vehicle, plugin
from tests.support.pty import Pty
from tests.support.vehicle import wait_for

WAYPOINTS = """QGC WPL 110
0\t1\t0\t16\t0\t0\t0\t0\t-37.9105\t145.1340\t100\t1
1\t0\t3\t16\t0\t0\t0\t0\t-37.9100\t145.1340\t100\t1
2\t0\t3\t16\t0\t0\t0\t0\t-37.9100\t145.1350\t100\t1
"""


class MavProxy:
    """MAVProxy run as a user runs it, its console typed into and read back."""

    def __init__(self, master: int | str, cwd: Path) -> None:
        """``master``: a connection string (the plug-in's ``mavproxy_master``), or the
        port of the vehicle's udpin endpoint on loopback."""
        mavproxy = Path(sys.executable).parent / "mavproxy.py"
        assert mavproxy.exists() or shutil.which("mavproxy.py"), "MAVProxy is a dev dependency"
        if isinstance(master, int):
            master = f"udpout:127.0.0.1:{master}"
        self.proc = subprocess.Popen(
            [sys.executable, str(mavproxy), f"--master={master}"],
            cwd=cwd,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        self.lines: list[str] = []
        self._reader = threading.Thread(
            target=lambda: self.lines.extend(self.proc.stdout), daemon=True
        )
        self._reader.start()

    def type(self, line: str) -> None:
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()

    def connected(self, vehicle) -> None:
        """Wait until MAVProxy talks to the link and has settled.

        MAVProxy's --cmd runs before it has heard the vehicle (and then resets its waypoint
        loader when the vehicle comes online), so commands are typed once it is connected.
        """
        wait_for(lambda: vehicle.row("link").frames_ok > 20, 30, "MAVProxy connected")
        time.sleep(2.0)

    def close(self) -> str:
        """Stop MAVProxy; everything it printed."""
        self.proc.terminate()
        try:
            self.proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self.proc.kill()  # MAVProxy's own threads can ignore SIGTERM while stdin is open
            self.proc.wait(timeout=5)
        self._reader.join(timeout=5)
        return "".join(self.lines)


@pytest.mark.timeout(120)
def test_mavproxy_param_fetch_wp_load_and_arm(vehicle_factory, tmp_path):
    port = free_udp_port()
    vehicle = vehicle_factory(client_vehicle(f"udpin://127.0.0.1:{port}", tmp_path / "state"))
    vehicle.wait_running("link")
    wp = tmp_path / "wp.txt"
    wp.write_text(WAYPOINTS)
    mission = tmp_path / "state" / "missions" / "mission.json"
    # Every parameter the config's plug-ins declare: the link's rates, the commander's
    # failsafes (battery too) and mode switch.
    said = f"Received {len(MavlinkLink.params) + len(CommanderPlugin.params)} parameters"
    mavproxy = MavProxy(port, tmp_path)
    try:
        mavproxy.connected(vehicle)
        for line in ("param fetch", f"wp load {wp}", "arm throttle"):
            mavproxy.type(line)
        wait_for(lambda: vehicle.row("flight").pid, 30, "MAVProxy's arm to start the flight group")
        wait_for(mission.exists, 20, "the uploaded mission stored")
        # MAVProxy asks MAVLink FTP for @PARAM/param.pck first (ArduPilot's packed list);
        # the vehicle's FTP has no such file and says so, and MAVProxy uses the protocol.
        wait_for(lambda: any(said in x for x in mavproxy.lines), 30, "param fetch")
        # The flight group starts before the acknowledgement has crossed back to MAVProxy.
        acked = "COMPONENT_ARM_DISARM: ACCEPTED"
        wait_for(lambda: any(acked in x for x in mavproxy.lines), 30, "the arm acknowledged")
    finally:
        output = mavproxy.close()
    assert said in output
    assert "COMPONENT_ARM_DISARM: ACCEPTED" in output, output
    assert len(json.loads(mission.read_text())) == 3


@pytest.mark.timeout(120)
def test_mavproxy_switches_modes_auto_rtl_loiter(vehicle_factory, tmp_path):
    from companion.messages import FlightMode

    port = free_udp_port()
    # MAVProxy's `mode NAME` passes pymavlink's PX4 mode tuple where a number belongs
    # (mavproxy_mode.cmd_mode → set_mode_px4), so a PX4-reporting vehicle cannot be switched
    # by name: MAVProxy users set the link's autopilot to "generic" (ArduPlane mode numbers,
    # both ways: MAVProxy names the heartbeat's mode, "Mode LOITER" and the prompt LOITER>).
    endpoint = f"udpin://127.0.0.1:{port}"
    vehicle = vehicle_factory(client_vehicle(endpoint, tmp_path / "state", autopilot="generic"))
    status = vehicle.bus.latest_reader("vehicle/status")
    wait_for(status.get, 20, "the commander up")
    wp = tmp_path / "wp.txt"
    wp.write_text(WAYPOINTS)
    seen = []
    mavproxy = MavProxy(port, tmp_path)
    try:
        mavproxy.connected(vehicle)
        mavproxy.type(f"wp load {wp}")
        wait_for((tmp_path / "state" / "missions" / "mission.json").exists, 20, "mission stored")
        for command, mode in (
            ("mode AUTO", FlightMode.MISSION),
            ("mode RTL", FlightMode.RTL),
            ("mode CRUISE", FlightMode.POSITION),  # had been taken for PX4's Stabilized (7)
            ("mode LOITER", FlightMode.LOITER),
        ):
            mavproxy.type(command)
            wait_for(lambda m=mode: status.get().mode == m, 10, command)
            seen.append(FlightMode(status.get().mode))
            name = command.split()[1]
            said = f"Mode {name}"  # MAVProxy's word on the heartbeat's new mode
            wait_for(lambda s=said: any(s in x for x in mavproxy.lines), 10, said)
    finally:
        output = mavproxy.close()
    assert seen == [FlightMode.MISSION, FlightMode.RTL, FlightMode.POSITION, FlightMode.LOITER]
    assert "LOITER>" in output and "Mode(" not in output, output


@pytest.mark.timeout(120)
def test_mavproxy_wp_save_writes_the_items_from_seq_0_and_they_load_back(vehicle_factory, tmp_path):
    # No home item (as PX4 and MAVLink's GENERIC): seq 0 is the first item to fly, so a file
    # without ArduPilot's home line is what `wp save` writes and `wp load` sends back.
    port = free_udp_port()
    endpoint = f"udpin://127.0.0.1:{port}"
    vehicle = vehicle_factory(client_vehicle(endpoint, tmp_path / "state", autopilot="generic"))
    vehicle.wait_running("link")
    wp, saved = tmp_path / "wp.txt", tmp_path / "saved.txt"
    wp.write_text(WAYPOINTS)
    mission = tmp_path / "state" / "missions" / "mission.json"
    mavproxy = MavProxy(port, tmp_path)
    try:
        mavproxy.connected(vehicle)
        mavproxy.type(f"wp load {wp}")
        wait_for(mission.exists, 20, "the uploaded mission stored")
        mavproxy.type("wp list")
        wait_for(lambda: any("Requesting 3 waypoints" in x for x in mavproxy.lines), 20, "list")
        time.sleep(2.0)
        mavproxy.type(f"wp save {saved}")
        wait_for(saved.exists, 20, "wp save")
    finally:
        mavproxy.close()
    rows = [line.split("\t") for line in saved.read_text().splitlines()[1:]]
    sent = [line.split("\t") for line in WAYPOINTS.splitlines()[1:]]

    def key(row: list[str]) -> tuple:
        return int(row[0]), int(row[3]), *(round(float(v), 6) for v in row[8:11])

    assert [key(r) for r in rows] == [key(s) for s in sent]


@pytest.mark.timeout(120)
def test_mavproxy_servo_set_moves_a_spare_output_once_armed(vehicle_factory, tmp_path):
    """``servo set 7 1900``, as an ArduPilot user releases a payload: refused with the
    reason while disarmed (the servo output runs only armed), then on the card's wire."""
    port, pty = free_udp_port(), Pty(tmp_path / "ttyServo")
    servos = plugin("servos", "actuators.minissc", group="flight", device=pty.link)
    vehicle = vehicle_factory(
        client_vehicle(f"udpin://127.0.0.1:{port}", tmp_path / "state", flight=servos)
    )
    vehicle.wait_running("link")
    os.set_blocking(pty.master, False)
    decoder, card = FrameDecoder(), {}

    def on_the_wire() -> bool:
        try:
            card.update(decoder.feed(os.read(pty.master, 4096)))
        except BlockingIOError:
            pass
        return card.get(6) == 229  # the card's servo 6 at (1900 - 1000) * 254 / 1000

    mavproxy = MavProxy(port, tmp_path)
    try:
        mavproxy.connected(vehicle)
        mavproxy.type("servo set 7 1900")
        refused = "Set servo: the servo output runs only while armed"
        wait_for(lambda: any(refused in x for x in mavproxy.lines), 30, "the refusal said")
        mavproxy.type("arm throttle")
        vehicle.wait_running("servos")
        mavproxy.type("servo set 7 1900")
        wait_for(on_the_wire, 30, "output 7 at 1900 us on the card's wire")
        acked = "DO_SET_SERVO: ACCEPTED"
        wait_for(lambda: any(acked in x for x in mavproxy.lines), 30, "the command acknowledged")
    finally:
        output = mavproxy.close()
    assert "DO_SET_SERVO: DENIED" in output, output
