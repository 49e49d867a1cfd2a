"""A waiting plug-in costs (almost) nothing, and `companion status` shows the table."""

from __future__ import annotations

import json
import subprocess
import sys
import time

import psutil

from companion.messages import CommandId, FlightMode, PluginState, VehicleCommand
from tests.protocol.mav_client import free_udp_port
from tests.support.configs import client_vehicle, pipeline
from tests.support.vehicle import REPO, assert_clean, companion_env, unique_namespace, wait_for


def test_a_waiting_plugin_uses_under_one_percent_of_a_core(vehicle_factory):
    vehicle = vehicle_factory(pipeline())
    pid = vehicle.wait_running("idle")
    proc = psutil.Process(pid)
    # Start-up (imports, bus ports) takes longer on a busy machine: the plug-in has up to a
    # minute to settle, then one 5 s window of waiting must cost under 1 % of a core. A
    # plug-in that polls never settles and fails here.
    shares = []
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline:
        before = proc.cpu_times()
        t0 = time.monotonic()
        time.sleep(5.0)
        after = proc.cpu_times()
        used = after.user + after.system - before.user - before.system
        shares.append(used / (time.monotonic() - t0))
        if shares[-1] < 0.01:
            break
    assert shares[-1] < 0.01, f"idle plug-in used {[f'{s:.2%}' for s in shares]} of a core"


def test_status_json_reports_every_plugin_with_state_pid_restarts_cpu(vehicle_factory):
    vehicle = vehicle_factory(pipeline(relay_group="flight"))
    pid = vehicle.wait_running("imu")
    wait_for(lambda: vehicle.row("imu").frames_ok > 0, 10, "the imu's counters")
    done = subprocess.run(
        [sys.executable, "-m", "companion", "status", "--json"],
        env=companion_env(vehicle.namespace),
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert done.returncode == 0, done.stderr
    table = json.loads(done.stdout)
    rows = {row["name"]: row for row in table["plugins"]}
    assert set(rows) == {"imu", "relay", "idle"}
    assert rows["imu"]["state"] == "running" and rows["imu"]["pid"] == pid
    assert rows["relay"]["state"] == "stopped" and rows["relay"]["group"] == "flight"
    assert rows["imu"]["restarts"] == 0
    assert rows["imu"]["frames_ok"] > 0
    assert 0.0 <= rows["imu"]["cpu_pct"] < 100.0
    assert table["supervisor_pid"] == vehicle.proc.pid
    assert table["flight_running"] is False


def test_status_human_table_and_silence(vehicle_factory, tmp_path):
    vehicle = vehicle_factory(pipeline())
    vehicle.wait_running("imu")
    shown = subprocess.run(
        [sys.executable, "-m", "companion", "status"],
        env=companion_env(vehicle.namespace),
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert shown.returncode == 0
    assert "imu" in shown.stdout and "running" in shown.stdout
    nobody = unique_namespace("nobody")
    silent = subprocess.run(
        [sys.executable, "-m", "companion", "status", "--timeout", "0.5"],
        env=companion_env(nobody),
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert silent.returncode == 1
    assert "no vehicle" in silent.stderr
    assert_clean(nobody)


def test_the_health_table_wakes_its_readers_for_news_not_for_counters(vehicle_factory):
    """Published every second, the table ends a sleeping reader's wait only when a plug-in
    starts, dies or restarts, or the vehicle arms: the commander, the link and the logger
    wait on it, and a vehicle on the bench should not wake them for its counters."""
    vehicle = vehicle_factory(pipeline())
    idle_pid = vehicle.wait_running("idle")
    vehicle.wait_running("imu")
    vehicle.wait_running("relay")
    bus = vehicle.bus
    health = bus.latest_reader("system/health")
    waiter = bus.waiter([health])
    try:
        wait_for(lambda: health.get() is not None, 10, "a health table")
        waiter.wait(0.0)  # whatever woke it before now is old news
        # Read after that wait: a table that came between a read and the wait is a sample
        # waiting, and ended the next wait at once (a wait returns for data as for news).
        first_us = health.get().t_us
        start = time.monotonic()
        waiter.wait(3.5)
        slept = time.monotonic() - start
        later = health.get()
        assert slept > 3.0, f"a table with new counters only ended a wait after {slept:.2f} s"
        assert later is not None and later.t_us > first_us, "the table is still published"
        psutil.Process(idle_pid).kill()
        start = time.monotonic()
        waiter.wait(10.0)
        assert time.monotonic() - start < 5.0, "a dead plug-in's row must wake its readers"
        row = health.get().rows()[[r.name for r in health.get().rows()].index(b"idle")]
        assert (row.pid, row.state) != (idle_pid, PluginState.RUNNING), "woken by other news"
    finally:
        waiter.close()


def test_a_disarmed_commander_wakes_status_readers_for_a_change_only(vehicle_factory, tmp_path):
    """The status goes out once a second while disarmed; a sleeping reader (the link) is
    woken by a new mode, not by the same status again."""
    port = free_udp_port()  # nobody listens there: the link only sends
    vehicle = vehicle_factory(client_vehicle(f"udpout://127.0.0.1:{port}", tmp_path))
    vehicle.wait_running("commander")
    bus = vehicle.bus
    status = bus.latest_reader("vehicle/status")
    waiter = bus.waiter([status])
    commands = bus.writer("link/commands")
    try:
        wait_for(lambda: status.get() is not None, 30, "a status")
        time.sleep(1.5)  # the first statuses (home set from the navigation) are old news
        waiter.wait(0.0)
        first_us = status.get().t_us
        start = time.monotonic()
        waiter.wait(3.5)
        slept = time.monotonic() - start
        assert status.get().t_us > first_us, "the status is still published"
        assert slept > 3.0, f"the same status again ended a wait after {slept:.2f} s"
        command = VehicleCommand(t_us=0, seq=1, command=int(CommandId.SET_MODE))
        command.param[0] = float(FlightMode.RTL)
        start = time.monotonic()
        commands.publish(command)
        waiter.wait(10.0)
        assert time.monotonic() - start < 5.0, "a new mode must wake the status's readers"
        assert status.get().mode == FlightMode.RTL
    finally:
        waiter.close()
