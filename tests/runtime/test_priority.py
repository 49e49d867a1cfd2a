"""When the CPU is short the flight chain goes first: each plug-in's process (or, composed,
its thread) runs at the nice value its class or its config entry asks for, and on the
hardware time base the flight chain runs under SCHED_FIFO (``realtime_priority``)."""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import psutil
import pytest

from companion.exec_control.config import ConfigError, load_config
from companion.exec_control.priority import realtime_priority
from companion.plugin import FLIGHT_NICE
from tests.support.configs import RELAY, TICKER, WAITING, plugin, vehicle_config
from tests.support.vehicle import REPO, wait_for

# A raise needs CAP_SYS_NICE; without it the plug-in stays at the supervisor's priority.
CAN_RAISE = os.geteuid() == 0
SCHED_OTHER, SCHED_FIFO = 0, 1


def expected(nice: int) -> int:
    return nice if nice >= 0 or CAN_RAISE else 0


def entries() -> list:
    return [
        replace(plugin("imu", TICKER, rate_hz=50.0), nice=FLIGHT_NICE),
        plugin("relay", RELAY),  # the test plug-in's class asks for nothing
        replace(plugin("idle", WAITING), nice=10),
    ]


def stat_fields(task: Path, *fields: int) -> tuple[int, ...]:
    """Fields of a thread's /proc/PID/task/TID/stat, numbered as proc(5) does."""
    stat = (task / "stat").read_text()
    after_name = stat[stat.rindex(")") + 2 :].split()  # field 3 on
    return tuple(int(after_name[f - 3]) for f in fields)


def thread_stats(pid: int, *fields: int) -> list[tuple[int, ...]]:
    """The fields of every thread of a process."""
    return [stat_fields(task, *fields) for task in Path(f"/proc/{pid}/task").iterdir()]


def thread_nices(pid: int) -> list[int]:
    """The nice value of every thread of a process (field 19)."""
    return [nice for (nice,) in thread_stats(pid, 19)]


def main_thread_policy(pid: int) -> tuple[int, ...]:
    """The main thread's scheduling policy and real-time priority (fields 41 and 40)."""
    return stat_fields(Path(f"/proc/{pid}/task/{pid}"), 41, 40)


def thread_policies(pid: int) -> list[tuple[int, ...]]:
    """Every thread's scheduling policy and real-time priority (fields 41 and 40)."""
    return thread_stats(pid, 41, 40)


def test_each_plugin_process_runs_at_its_nice_value(vehicle_factory):
    vehicle = vehicle_factory(vehicle_config("prio", *entries()))
    pids = {name: vehicle.wait_running(name) for name in ("imu", "relay", "idle")}
    # A process sets its own priority before it starts its plug-in: read it once each has
    # reported its first counters (the health table shows a pid from the fork on).
    wait_for(lambda: all(vehicle.row(name).counted_us > 0 for name in pids), 60, "counters")
    nices = {name: psutil.Process(pid).nice() for name, pid in pids.items()}
    assert nices == {"imu": expected(FLIGHT_NICE), "relay": 0, "idle": 10}
    assert psutil.Process(vehicle.proc.pid).nice() == 0  # the supervisor keeps its own
    # On the hardware clock the flight chain's process is also a real-time one.
    fifo = (SCHED_FIFO, 10) if CAN_RAISE else (SCHED_OTHER, 0)
    policies = {name: main_thread_policy(pid) for name, pid in pids.items()}
    assert policies == {"imu": fifo, "relay": (SCHED_OTHER, 0), "idle": (SCHED_OTHER, 0)}


def test_composed_plugins_keep_their_own_nice_values_on_their_threads(vehicle_factory):
    composed = [replace(e, process="core") for e in entries()]
    vehicle = vehicle_factory(vehicle_config("prio", *composed))
    pid = vehicle.wait_running("imu")
    # The main thread (which only waits for signals) and the relay's stay at 0.
    wanted = sorted([expected(FLIGHT_NICE), 0, 10])
    wait_for(lambda: set(wanted) <= set(thread_nices(pid)), 10, "the threads' priorities")
    assert expected(FLIGHT_NICE) in thread_nices(pid) and 10 in thread_nices(pid)
    # The flight chain's thread alone is a real-time one: the main thread, the relay's and
    # the idle one's (and their stats threads) are not.
    policies = thread_policies(pid)
    fifo = [p for p in policies if p[0] == SCHED_FIFO]
    assert fifo == ([(SCHED_FIFO, 10)] if CAN_RAISE else [])
    assert len(policies) - len(fifo) >= 3


@pytest.mark.parametrize(
    ("nice", "vehicle", "wanted"),
    [
        (FLIGHT_NICE, {"clock": "monotonic", "realtime_priority": 10}, 10),
        (FLIGHT_NICE, {"realtime_priority": 20}, 20),  # the default clock is the hardware's
        (FLIGHT_NICE, {"clock": "monotonic", "realtime_priority": 0}, 0),  # asked for none
        (FLIGHT_NICE, {"clock": "sim", "realtime_priority": 10}, 0),  # lockstep: no core
        (0, {"clock": "monotonic", "realtime_priority": 10}, 0),  # not the flight chain
        (10, {"clock": "monotonic", "realtime_priority": 10}, 0),
    ],
)
def test_only_the_flight_chain_on_the_hardware_clock_asks_for_real_time(nice, vehicle, wanted):
    assert realtime_priority(nice, vehicle) == wanted


def test_a_raise_refused_by_the_system_leaves_the_plugin_running_at_its_parents():
    """As an unprivileged user without CAP_SYS_NICE (a service unit that grants none): the
    vehicle says so once, and every plug-in runs (the raised ones at nice 0)."""
    code = (
        "import logging, os\n"
        "from types import SimpleNamespace as S\n"
        "from companion.exec_control.priority import apply_nice, apply_priority,"
        " note_refused_raises\n"
        "logging.basicConfig(level=logging.INFO)\n"
        # Imported first: the nobody user cannot read the interpreter's files here.
        + ("os.setgid(65534); os.setuid(65534)\n" if CAN_RAISE else "")
        + "note_refused_raises([S(name='imu', nice=-5), S(name='nav', nice=-5),"
        " S(name='logger', nice=3)])\n"
        "print(apply_priority('nav', -5, {'clock': 'monotonic', 'realtime_priority': 10}))\n"
        "print(apply_nice('imu', -5), apply_nice('logger', 3))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["nice", "0", "0", "3"]
    said = [ln for ln in done.stderr.splitlines() if "needs CAP_SYS_NICE" in ln]
    assert len(said) == 1 and "imu, nav run at the same priority" in said[0], done.stderr
    # The supervisor's one line covers real-time too: no plug-in repeats it.
    assert "SCHED_FIFO" not in done.stderr


def test_flight_chain_classes_ask_for_the_flight_priority_and_a_config_can_override(tmp_path):
    path = tmp_path / "v.toml"
    path.write_text(
        vehicle_config(
            "v",
            plugin("imu", "sensors.serial_imu", device="/dev/null"),
            replace(plugin("link", "link.mavlink"), nice=0),
            replace(plugin("log", "system.logger"), nice=12),
        )
    )
    nice = {spec.name: spec.nice for spec in load_config(path).plugins}
    assert nice == {"imu": FLIGHT_NICE, "link": 0, "log": 12}


@pytest.mark.parametrize("bad", [50, -1, "high", 1.5])
def test_a_realtime_priority_out_of_range_is_refused_with_its_line(tmp_path, bad):
    path = tmp_path / "bad.toml"
    path.write_text(vehicle_config("v", plugin("imu", TICKER, rate_hz=5.0), realtime_priority=bad))
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert "realtime_priority" in str(info.value)


@pytest.mark.parametrize("bad", [25, -21, "high", 1.5, True])
def test_a_nice_value_out_of_range_is_refused_with_its_line(tmp_path, bad):
    path = tmp_path / "bad.toml"
    path.write_text(vehicle_config("v", replace(plugin("imu", TICKER, rate_hz=5.0), nice=bad)))
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert "nice" in str(info.value) and "-20" in str(info.value)
