"""Silent and garbled devices found in the health tables, for the pre-arm checks."""

from __future__ import annotations

from companion.control.device_watch import DeviceWatch
from companion.control.prearm import Readiness, failures
from companion.messages import PluginState, SystemHealth

PLUGINS = {
    "sensors.nmea_gps": {"device": "/dev/gps", "baud": 4800},
    "sensors.os3000": {"device": "/dev/compass", "baud": 19200},
    "nav.ins_ekf": {"publish_hz": 50.0},
    "actuators.minissc": {"device": "/dev/servos", "baud": 9600},
}
ROWS = (("gps", "sensors.nmea_gps", "core"), ("compass", "sensors.os3000", "core"),
        ("nav", "nav.ins_ekf", "core"), ("servos", "actuators.minissc", "flight"))  # fmt: skip


def table(
    t_s: float,
    counts: dict[str, tuple[int, int, int]],
    pid: int = 100,
    counted_s: dict[str, float] | None = None,
) -> SystemHealth:
    """A health table at ``t_s``: counts are (bytes, frames ok, frames bad) by name, each
    counted at the table's time unless ``counted_s`` gives the plug-in's own time."""
    msg = SystemHealth(t_us=round(t_s * 1e6), count=len(ROWS))
    for i, (name, kind, group) in enumerate(ROWS):
        row = msg.plugins[i]
        row.name, row.kind, row.group = name.encode(), kind.encode(), group.encode()
        row.state, row.pid = int(PluginState.RUNNING), pid
        row.bytes_in, row.frames_ok, row.frames_bad = counts.get(name, (0, 0, 0))
        row.counted_us = round((counted_s or {}).get(name, t_s) * 1e6)
    return msg


def watch_over(seconds: int, per_second: dict[str, tuple[int, int, int]], pid=100) -> DeviceWatch:
    watch = DeviceWatch(PLUGINS)
    for t in range(seconds + 1):
        counts = {k: (b * t, ok * t, bad * t) for k, (b, ok, bad) in per_second.items()}
        watch.update(table(t, counts, pid))
    return watch


def test_healthy_devices_pass_and_only_device_plugins_running_now_are_judged():
    watch = watch_over(5, {"gps": (400, 5, 0), "compass": (600, 20, 0)})
    assert watch.failures() == []  # nav has no device; the servo card is not running yet


def test_a_silent_device_is_named_once_the_window_is_covered():
    young = watch_over(2, {"gps": (400, 5, 0)}).failures()  # not 3 s yet: heard or not
    assert young == ["compass: waiting for data from its device"]
    assert watch_over(3, {"gps": (400, 5, 0)}).failures() == ["compass: no data from its device"]


def test_bytes_without_frames_and_mostly_bad_frames_are_garbled():
    wrong_baud = watch_over(4, {"gps": (300, 0, 1), "compass": (600, 20, 0)})
    assert wrong_baud.failures() == ["gps: garbled data (wrong baud rate?)"]
    noisy = watch_over(4, {"gps": (400, 5, 0), "compass": (600, 12, 8)})
    assert noisy.failures() == ["compass: garbled data, 24 of 60 frames bad"]
    a_few = watch_over(4, {"gps": (400, 5, 0), "compass": (600, 20, 1)})
    assert a_few.failures() == []  # 1 in 21: a line's ordinary loss


def test_a_device_that_fell_silent_is_named_and_a_restarted_plugin_is_judged_afresh():
    watch = watch_over(5, {"gps": (400, 5, 0), "compass": (600, 20, 0)})
    for t in range(6, 10):  # the compass stops at 5 s
        watch.update(table(t, {"gps": (400 * t, 5 * t, 0), "compass": (3000, 100, 0)}))
    assert watch.failures() == ["compass: no data from its device"]
    watch.update(table(10, {"gps": (4000, 50, 0)}, pid=200))  # every plug-in restarted
    assert watch.failures() == ["compass: waiting for data from its device"]
    watch.update(table(11, {"gps": (4400, 55, 0), "compass": (60, 1, 0)}, pid=200))
    assert watch.failures() == []  # one good frame from the new process: no verdict yet


def test_counters_not_reported_again_are_not_silence_however_far_the_table_ran():
    # A lockstep simulation at 10x: the tables are 10 s of vehicle time apart, and under
    # load a plug-in's once-a-second report can miss one (the pre-arm refused MAVSDK's arm
    # with "compass: no data from its device" while the compass talked all along).
    watch = DeviceWatch(PLUGINS)
    reports = [(1, 1), (10, 10), (20, 10), (30, 30), (40, 40)]  # (table s, compass s)
    for t, counted in reports:
        counts = {"gps": (400 * t, 5 * t, 0), "compass": (600 * counted, 20 * counted, 0)}
        watch.update(table(t, counts, counted_s={"compass": counted}))
        assert watch.failures() == [], t
    # ... while counters that are reported again unchanged are silence.
    watch.update(table(50, {"gps": (20000, 250, 0), "compass": (24000, 800, 0)}))
    assert watch.failures() == ["compass: no data from its device"]


def test_an_excused_kind_is_not_judged_silent_or_waiting():
    # The link excuses the RC receiver while a ground station's joystick flies.
    assert watch_over(2, {"gps": (400, 5, 0)}).failures(excused=("sensors.os3000",)) == []
    silent = watch_over(4, {"gps": (400, 5, 0)})
    assert silent.failures(excused=("sensors.os3000",)) == []
    assert silent.failures() == ["compass: no data from its device"]


def test_the_same_table_twice_counts_once_and_the_reason_reaches_prearm():
    watch = DeviceWatch(PLUGINS)
    for t in (0, 1, 1, 1, 2, 3):
        watch.update(table(t, {"gps": (400 * t, 5 * t, 0), "compass": (600 * t, 20 * t, 0)}))
    assert watch.failures() == []
    silent = watch_over(3, {"gps": (400, 5, 0)}).failures()
    reasons = failures(
        Readiness(now_us=0, devices=silent), {"ARMING_GPS_EPH": 5.0, "ARMING_STALE_S": 1.0}
    )
    assert "compass: no data from its device" in reasons


def test_a_held_simulation_clock_still_takes_newer_counters():
    """``companion sim --hold-at``: the vehicle time stops while a ground station arms, and
    every table after that carries the same time. The counters in them are newer: a table
    made before the plug-ins' first reports must not refuse arming for ever (a CI run's
    vehicle, held at 10 s, never armed)."""
    watch = DeviceWatch(PLUGINS)
    watch.update(table(0, {}))  # the plug-ins just started: nothing heard yet
    watch.update(table(10, {"gps": (400, 1, 0)}, counted_s={"gps": 10, "compass": 0}))
    assert watch.failures() == ["compass: waiting for data from its device"]
    for _ in range(3):  # held at 10 s: the compass's report comes in a later table
        watch.update(table(10, {"gps": (400, 1, 0), "compass": (600, 20, 0)}))
    assert watch.failures() == []
    # An older report than the one held is not taken over it.
    watch.update(table(10, {"gps": (400, 1, 0)}, counted_s={"gps": 9, "compass": 9}))
    assert watch.failures() == []
