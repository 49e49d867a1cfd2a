"""Plug-ins composed into one OS process by the config: data flows as before, a plug-in that
raises is restarted alone, a killed process is restarted whole, START/STOP still toggle
exactly the flight group, and the status shows which process each plug-in runs in."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from dataclasses import replace

import psutil

from companion.messages import CommandId, CommandResult, PluginState, VehicleCommand
from tests.support.configs import CRASH_AFTER, RELAY, TICKER, WAITING, plugin, vehicle_config
from tests.support.vehicle import REPO, companion_env, wait_for


def composed(*entries, process: str = "core"):
    """The entries, each placed in ``process``."""
    return [replace(e, process=process) for e in entries]


def pipeline_in_one_process(relay_group: str = "core") -> str:
    core = composed(plugin("imu", TICKER, rate_hz=50.0), plugin("idle", WAITING))
    relay = plugin("relay", RELAY, group=relay_group)
    relay = replace(relay, process="flight" if relay_group == "flight" else "core")
    return vehicle_config("composed", *core, relay)


def newest_nav_t(reader) -> int:
    value = reader.get()
    return -1 if value is None else value.t_us


def test_composed_plugins_share_one_process_and_data_flows(vehicle_factory):
    vehicle = vehicle_factory(pipeline_in_one_process())
    nav = vehicle.bus.latest_reader("nav/state")
    pid = vehicle.wait_running("imu")
    wait_for(lambda: newest_nav_t(nav) > 0, 10, "nav/state from the relay")
    rows = {name: vehicle.row(name) for name in ("imu", "relay", "idle")}
    assert {r.pid for r in rows.values()} == {pid}
    assert {r.process for r in rows.values()} == {b"core"}
    assert all(r.state == PluginState.RUNNING for r in rows.values())
    # One process for three plug-ins (the fork server is the supervisor's other child).
    kids = {c.pid for c in psutil.Process(vehicle.proc.pid).children()}
    assert pid in kids and len(kids) <= 2
    wait_for(lambda: vehicle.row("relay").frames_ok > 0, 5, "the relay's own counters")

    out = subprocess.run(
        [sys.executable, "-m", "companion", "status", "--json"],
        env=companion_env(vehicle.namespace),
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=30,
    )
    table = {row["name"]: row for row in json.loads(out.stdout)["plugins"]}
    assert {table[n]["process"] for n in ("imu", "relay", "idle")} == {"core"}


def test_a_composed_plugin_that_raises_is_restarted_alone(vehicle_factory):
    entries = composed(
        plugin("imu", TICKER, rate_hz=50.0),
        plugin("relay", RELAY),
        plugin("crash", CRASH_AFTER, steps=3),
    )
    vehicle = vehicle_factory(vehicle_config("crashy", *entries))
    nav = vehicle.bus.latest_reader("nav/state")
    pid = vehicle.wait_running("crash")
    wait_for(lambda: (r := vehicle.row("crash")) and r.restarts >= 3, 20, "three restarts")
    # The back-off grows (0, 0.1, 0.2, 0.4 s ...): a crash every 30 ms would be 30 a second.
    assert vehicle.row("crash").restarts < 12
    assert vehicle.row("crash").pid == pid, "the process itself did not die"
    for name in ("imu", "relay"):
        row = vehicle.row(name)
        assert (row.pid, row.restarts, row.state) == (pid, 0, PluginState.RUNNING)
    before = newest_nav_t(nav)
    wait_for(lambda: newest_nav_t(nav) > before, 5, "the others' data still flowing")
    assert vehicle.proc.poll() is None


def test_a_killed_composed_process_is_restarted_whole(vehicle_factory):
    vehicle = vehicle_factory(pipeline_in_one_process())
    nav = vehicle.bus.latest_reader("nav/state")
    old = vehicle.wait_running("imu")
    wait_for(lambda: newest_nav_t(nav) > 0, 10, "nav/state before the kill")
    supervisor = psutil.Process(vehicle.proc.pid)
    others = {c.pid for c in supervisor.children()} - {old}

    killed_at = time.monotonic()
    os.kill(old, signal.SIGKILL)

    def new_process() -> int:
        fresh = {c.pid for c in supervisor.children()} - others - {old}
        return next(iter(fresh), 0)

    wait_for(new_process, 3, "the process started again", period_s=0.002)
    # Restarted at once (SIGCHLD wakes the supervisor); benchmarks/compose_restart.py times it.
    assert time.monotonic() - killed_at < 1.0
    new = wait_for(lambda: (r := vehicle.row("relay")) and r.pid not in (0, old) and r.pid, 5,
                   "the new process in the table")  # fmt: skip
    assert {vehicle.row(n).pid for n in ("imu", "idle", "relay")} == {new}
    assert all(vehicle.row(n).restarts == 1 for n in ("imu", "idle", "relay"))
    before = newest_nav_t(nav)
    wait_for(lambda: newest_nav_t(nav) > before, 5, "data flowing after the restart")


def send(vehicle, command: CommandId, seq: int):
    vehicle.commands.publish(VehicleCommand(t_us=0, seq=seq, command=int(command)))
    return wait_for(lambda: next((a for a in vehicle.acks.take() if a.seq == seq), None), 5,
                    f"ack of {command.name}")  # fmt: skip


def test_start_and_stop_toggle_exactly_the_composed_flight_group(vehicle_factory):
    flight = composed(plugin("relay", RELAY, group="flight"),
                      plugin("wait", WAITING, group="flight"), process="flight")  # fmt: skip
    core = composed(plugin("imu", TICKER, rate_hz=50.0), plugin("idle", WAITING))
    vehicle = vehicle_factory(vehicle_config("startstop", *core, *flight))
    vehicle.commands = vehicle.bus.writer("link/commands")
    vehicle.acks = vehicle.bus.queue_reader("link/command_acks")
    nav = vehicle.bus.latest_reader("nav/state")
    core_pid = vehicle.wait_running("imu")
    assert vehicle.row("relay").state == PluginState.STOPPED
    assert nav.wait(0.5) is None, "nothing flies before START"

    assert send(vehicle, CommandId.START, 1).result == CommandResult.ACCEPTED
    wait_for(lambda: vehicle.row("wait").state == PluginState.RUNNING, 5, "flight running")
    flight_pid = vehicle.row("relay").pid
    assert flight_pid not in (0, core_pid) and vehicle.row("wait").pid == flight_pid
    assert wait_for(lambda: nav.wait(0.2), 5, "nav/state from the flight group")

    assert send(vehicle, CommandId.STOP, 2).result == CommandResult.ACCEPTED
    wait_for(lambda: vehicle.row("relay").state == PluginState.STOPPED, 5, "flight stopped")
    assert (vehicle.row("relay").pid, vehicle.row("wait").pid) == (0, 0)
    assert not psutil.pid_exists(flight_pid) or psutil.Process(flight_pid).status() == "zombie"
    assert {vehicle.row(n).pid for n in ("imu", "idle")} == {core_pid}
    assert vehicle.row("imu").restarts == 0


def both_groups_in_one_process(vehicle_factory, *flight):
    """A vehicle whose one process holds a core ticker and the ``flight`` plug-ins, with
    its command writer, its ack reader, the nav/state reader and the process's pid."""
    entries = composed(plugin("imu", TICKER, rate_hz=50.0), *flight, process="vehicle")
    vehicle = vehicle_factory(vehicle_config("onebox", *entries))
    vehicle.commands = vehicle.bus.writer("link/commands")
    vehicle.acks = vehicle.bus.queue_reader("link/command_acks")
    return vehicle, vehicle.bus.latest_reader("nav/state"), vehicle.wait_running("imu")


def test_start_and_stop_run_the_flight_plugins_inside_a_process_that_holds_both_groups(
    vehicle_factory,
):
    vehicle, nav, pid = both_groups_in_one_process(
        vehicle_factory,
        plugin("relay", RELAY, group="flight"),
        plugin("wait", WAITING, group="flight"),
    )
    assert (vehicle.row("relay").state, vehicle.row("relay").pid) == (PluginState.STOPPED, 0)
    assert nav.wait(0.5) is None, "nothing flies before START"

    for round_ in range(2):  # started, stopped and started again: fresh instances each time
        seq = 10 * round_
        assert send(vehicle, CommandId.START, seq + 1).result == CommandResult.ACCEPTED
        wait_for(lambda: vehicle.row("wait").state == PluginState.RUNNING, 5, "flight running")
        assert {vehicle.row(n).pid for n in ("imu", "relay", "wait")} == {pid}
        assert wait_for(lambda: nav.wait(0.2), 5, "nav/state from the flight plug-in")

        assert send(vehicle, CommandId.STOP, seq + 2).result == CommandResult.ACCEPTED
        wait_for(lambda: vehicle.row("relay").state == PluginState.STOPPED, 5, "flight stopped")
        time.sleep(0.3)  # the relay's last step ends within its wait
        nav.get()
        assert nav.wait(0.5) is None, "the relay still runs after STOP"
    imu = vehicle.row("imu")
    assert (imu.pid, imu.restarts, imu.state) == (pid, 0, PluginState.RUNNING)
    assert all(vehicle.row(n).restarts == 0 for n in ("relay", "wait"))


def test_a_process_holding_both_groups_killed_in_the_air_runs_its_flight_plugins_at_once(
    vehicle_factory,
):
    vehicle, nav, old = both_groups_in_one_process(
        vehicle_factory, plugin("relay", RELAY, group="flight")
    )
    assert send(vehicle, CommandId.START, 1).result == CommandResult.ACCEPTED
    wait_for(lambda: nav.wait(0.2), 5, "nav/state from the flight plug-in")

    os.kill(old, signal.SIGKILL)
    new = wait_for(lambda: (r := vehicle.row("relay")) and r.pid not in (0, old) and r.pid, 5,
                   "the new process in the table")  # fmt: skip
    # No second START: the new process was told the flight group runs.
    wait_for(lambda: (v := nav.wait(0.2)) and v.t_us > 0 and vehicle.row("imu").pid == new, 5,
             "nav/state from the restarted process's flight plug-in")  # fmt: skip
    assert vehicle.row("relay").state == PluginState.RUNNING
