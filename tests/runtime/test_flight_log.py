"""system.logger records a real vehicle's bus to a ULog file that survives kill -9."""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import time
from pathlib import Path

import pytest
from pyulog import ULog
from pyulog.exceptions import ULogException

from companion.messages import CommandId, SimClock, VehicleCommand
from tests.support.configs import flight_group, plugin, vehicle_config
from tests.support.vehicle import Vehicle, wait_for

ROWS = 200


def make_sensor_log(path: Path) -> None:
    """IMU samples numbered by their ax, 50 Hz, a GPS fix every tenth sample."""
    lines = ["t,kind,ax,ay,az,gx,gy,gz,lat,lon,alt_m,vn,ve,vd,fix,hdop,mx,my,mz,baro_alt_m"]
    for i in range(ROWS):
        lines.append(f"{i * 0.02:.3f},imu,{i},0,-9.81,0,0,0,,,,,,,,,,,,")
        if i % 10 == 0:
            lines.append(
                f"{i * 0.02:.3f},gps,,,,,,,-37.91,{145.134 + i * 1e-5:.5f},100,1,2,,3,1,,,,"
            )
    path.write_text("\n".join(lines) + "\n")


def read_log(logs: Path) -> ULog | None:
    """The newest log as pyulog reads it (None while there is none with IMU samples)."""
    files = sorted(logs.glob("*.ulg"))
    if not files:
        return None
    try:
        ulog = ULog(str(files[-1]))
        ulog.get_dataset("sensors_imu")
    except (IndexError, ValueError, KeyError, ULogException):  # not written far enough yet
        return None
    return ulog


def imu_ax(ulog: ULog | None) -> list[float]:
    if ulog is None:
        return []
    return [float(x) for x in ulog.get_dataset("sensors_imu").data["ax_m_s2"]]


def kill_everything(vehicle: Vehicle) -> None:
    """A power cut: every process of the vehicle at once, no chance to close a file."""
    for pid in vehicle.all_pids():
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    assert vehicle.proc is not None
    vehicle.proc.wait(timeout=10)


class PublishedImu:
    """The IMU samples published on the bus, as the test's own reader sees them, each
    with the sensor time elapsed since the first (a replay that loops starts its stamps
    again from the log's first one at once: no time passes at the wrap)."""

    def __init__(self, vehicle: Vehicle) -> None:
        assert vehicle.bus is not None
        self.reader = vehicle.bus.queue_reader("sensors/imu")
        self.ax: list[float] = []
        self.elapsed_us: list[int] = []
        self.last_us: int | None = None

    def read(self) -> int:
        for msg in self.reader.drain():
            step = 0 if self.last_us is None else max(int(msg.t_us) - self.last_us, 0)
            self.elapsed_us.append((self.elapsed_us[-1] if self.elapsed_us else 0) + step)
            self.last_us = int(msg.t_us)
            self.ax.append(float(msg.ax_m_s2))
        assert self.reader.lost == 0, "the test's reader fell behind"
        return len(self.ax)


# The promise: a power cut loses at most the last flush interval (1 s by default) of
# samples. The margin is the logger's read period (20-100 ms) and the scheduling of a busy
# machine between the drain it last flushed and the flush itself.
MARGIN_S = 0.3


@pytest.mark.parametrize("flush_s", [0.2, 1.0])
def test_an_armed_flight_is_logged_and_readable_after_kill_9(vehicle_factory, tmp_path, flush_s):
    sensor_log = tmp_path / "flight.csv"
    make_sensor_log(sensor_log)
    state = tmp_path / "state"
    vehicle = vehicle_factory(
        vehicle_config(
            "logged",
            plugin("logger", "system.logger", flush_s=flush_s),
            # In the flight group: it plays (in a loop) once armed, as sensors would fly.
            plugin("replay", "sensors.replay", group="flight", file=sensor_log, loop=True),
            state_dir=state,
            airframe="J3Cub",
        )
    )
    # Armed only once the logger reads (its first step done), so it sees the first sample.
    wait_for(lambda: (r := vehicle.row("logger")) is not None and r.step_p50_us > 0, 30, "logger")
    published = PublishedImu(vehicle)  # from before the arming: every sample the replay plays
    vehicle.bus.writer("link/commands").publish(
        VehicleCommand(t_us=0, seq=1, command=int(CommandId.START))
    )
    logs = state / "logs"
    # The samples reach the disk while the vehicle runs: more than one pass of the log.
    wait_for(
        lambda: published.read() and len(imu_ax(read_log(logs))) > ROWS + 10, 30, "a log on disk"
    )
    published.read()  # the newest sample published just before the cut
    kill_everything(vehicle)

    files = sorted(logs.glob("*.ulg"))
    assert [p.name for p in files] == ["0001_armed.ulg"]  # no boot log unless asked
    ulog = read_log(logs)
    ax = imu_ax(ulog)
    assert len(ax) > ROWS + 10
    assert ax == [float(i % ROWS) for i in range(len(ax))]  # in order, none lost or repeated
    # The cut lost at most the last flush interval: the newest sample on disk is the one
    # published that much sensor time before the newest the bus carried.
    on_disk = min(len(ax), len(published.ax))  # the cut may come after a newer one
    assert published.ax[:on_disk] == ax[:on_disk]
    lost_s = (published.elapsed_us[-1] - published.elapsed_us[on_disk - 1]) / 1e6
    logging.getLogger(__name__).info("kill -9 lost %.3f s of IMU samples", lost_s)
    assert lost_s <= flush_s + MARGIN_S, (lost_s, len(published.ax), len(ax))
    assert ulog is not None
    assert ulog.msg_info_dict["vehicle_name"] == "logged"
    assert ulog.msg_info_dict["sys_name"] == "companion"
    assert ulog.msg_info_dict["airframe"] == "J3Cub"  # the vehicle's, [vehicle] airframe
    gps = ulog.get_dataset("sensors_gps").data
    assert len(gps["timestamp"]) >= ROWS // 10
    assert [round(float(x), 5) for x in gps["lon_deg"][:3]] == [145.134, 145.1341, 145.1342]
    health = ulog.get_dataset("system_health").data
    assert max(health["flight_running"]) == 1


def test_from_boot_logs_while_disarmed(vehicle_factory, tmp_path):
    state = tmp_path / "state"
    vehicle = vehicle_factory(
        vehicle_config(
            "boot",
            plugin("logger", "system.logger", from_boot=True, flush_s=0.2),
            plugin("imu", "tests.support.plugins:Ticker", rate_hz=100.0),
            state_dir=state,
        )
    )
    logs = state / "logs"
    wait_for(lambda: len(imu_ax(read_log(logs))) >= 50, 30, "a boot log on disk")
    vehicle.stop()
    ulog = read_log(logs)
    assert [p.name for p in sorted(logs.glob("*.ulg"))] == ["0001_boot.ulg"]
    ax = imu_ax(ulog)
    # The Ticker numbers its samples: from the first the logger saw, none lost or repeated.
    assert len(ax) >= 50
    assert ax == [ax[0] + i for i in range(len(ax))]


def test_a_simulated_vehicle_logs_on_one_time_base(vehicle_factory, tmp_path):
    """In SITL every stamp is simulation time, the supervisor's health table included: a
    log that mixed in the host's uptime would span hours in Flight Review."""
    state = tmp_path / "state"
    vehicle = vehicle_factory(
        vehicle_config(
            "simtime",
            plugin("logger", "system.logger", from_boot=True, flush_s=0.2),
            plugin("imu", "tests.support.plugins:Ticker", rate_hz=100.0),
            state_dir=state,
            clock="sim",
        )
    )
    assert vehicle.bus is not None
    clock = vehicle.bus.writer("sim/clock")
    first_us = t_us = 5_000_000_000  # far from this host's uptime

    def health_logged() -> bool:
        nonlocal t_us
        t_us += 10_000
        clock.publish(SimClock(t_us=t_us))
        ulog = read_log(state / "logs")
        try:
            return ulog is not None and len(ulog.get_dataset("system_health").data["timestamp"]) > 2
        except (KeyError, IndexError, ValueError):
            return False

    wait_for(health_logged, 60, "health tables in the log", period_s=0.01)
    vehicle.stop()
    ulog = read_log(state / "logs")
    assert ulog is not None
    for data in ulog.data_list:
        stamps = [int(t) for t in data.data["timestamp"]]
        assert all(first_us <= t <= t_us for t in stamps if t), (data.name, stamps[:3])
    assert {d.name for d in ulog.data_list} >= {"system_health", "sensors_imu"}


def test_lost_samples_are_counted_once_and_marked_in_the_log(vehicle_factory, tmp_path):
    """Bursts larger than the IMU queue: the samples the logger lost are its status row's
    ``dropped`` (once, not twice) and leave ULog dropouts and a warning where they were."""
    state = tmp_path / "state"
    vehicle = vehicle_factory(
        vehicle_config(
            "lossy",
            plugin("logger", "system.logger", from_boot=True, flush_s=0.2, period_s=0.1),
            plugin("imu", "tests.support.plugins:Burst", size=2000, bursts=3),
            state_dir=state,
        )
    )
    logs = state / "logs"
    wait_for(lambda: len(imu_ax(read_log(logs))) >= 64, 30, "a burst in the log")

    def missing() -> int:
        ax = imu_ax(read_log(logs))  # numbered from 1: the gaps are what was lost
        return int(ax[-1] - ax[0] + 1) - len(ax) if ax else -1

    # All three bursts written and counted (the row comes once a second, the bursts 0.5 s
    # apart: the row can match the log after the second burst, before the third is sent).
    wait_for(
        lambda: (
            (r := vehicle.row("logger")) is not None
            and r.dropped > 0
            and r.dropped == missing()
            and imu_ax(read_log(logs))[-1:] == [3 * 2000]
        ),
        30,
        "the status row's dropped count equal to the samples missing from the log",
    )
    vehicle.stop()
    ulog = read_log(logs)
    assert ulog is not None
    ax = imu_ax(ulog)
    assert ax[-1] == 3 * 2000  # the last sample of the last burst is there
    assert ulog.dropouts and all(d.duration >= 0 for d in ulog.dropouts)
    warnings = [m.message for m in ulog.logged_messages if "logger lost" in m.message]
    counted = sum(int(text.split()[2]) for text in warnings)
    assert counted == int(ax[-1] - ax[0] + 1) - len(ax)


def test_samples_lost_before_arming_are_marked_in_the_armed_log(vehicle_factory, tmp_path):
    """The samples kept from before the arming go into the flight's log with their gaps:
    a loss while disarmed is a dropout and a warning there too, not a silent hole."""
    state = tmp_path / "state"
    vehicle = vehicle_factory(
        vehicle_config(
            "prearm_lossy",
            plugin("logger", "system.logger", prearm_samples=20_000, period_s=0.1),
            plugin("imu", "tests.support.plugins:Burst", size=2000, bursts=2),
            flight_group(),
            state_dir=state,
        )
    )
    # Both bursts published and some of them lost by the logger, all before the arming.
    wait_for(lambda: (r := vehicle.row("imu")) is not None and r.frames_ok >= 2, 30, "two bursts")
    wait_for(lambda: (r := vehicle.row("logger")) is not None and r.dropped > 0, 30, "a loss")
    vehicle.bus.writer("link/commands").publish(
        VehicleCommand(t_us=0, seq=1, command=int(CommandId.START))
    )
    logs = state / "logs"
    wait_for(lambda: imu_ax(read_log(logs)), 30, "the armed log with the samples kept")
    vehicle.stop()
    ulog = read_log(logs)
    ax = imu_ax(ulog)
    missing = int(ax[-1] - ax[0] + 1) - len(ax)
    assert missing > 0 and ax[-1] == 4000  # a hole, and the last sample published is there
    warnings = [m.message for m in ulog.logged_messages if "logger lost" in m.message]
    assert sum(int(text.split()[2]) for text in warnings) == missing
    assert ulog.dropouts


def voluntary_switches(pid: int) -> int:
    """Times the process's main thread went to sleep (each ends in one wake-up)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("voluntary_ctxt_switches"):
            return int(line.split()[1])
    raise AssertionError("no context switch count")


def test_on_a_quiet_bench_the_logger_sleeps_until_a_sample_comes(vehicle_factory, tmp_path):
    """A trickle (2 samples a second) wakes the logger for each sample, not 4-5 times a
    second on a timer; what it cannot lose it need not look for."""
    vehicle = vehicle_factory(
        vehicle_config(
            "trickle",
            plugin("logger", "system.logger"),
            plugin("imu", "tests.support.plugins:Ticker", rate_hz=2.0),
            state_dir=tmp_path / "state",
        )
    )
    pid = vehicle.wait_running("logger")
    wait_for(lambda: vehicle.row("logger").step_p50_us > 0, 30, "the logger stepping")
    time.sleep(2.0)  # its reads have measured the trickle
    before, start = voluntary_switches(pid), time.monotonic()
    time.sleep(8.0)
    per_s = (voluntary_switches(pid) - before) / (time.monotonic() - start)
    # Two samples and its counters once a second are 3 wake-ups; on a timer it woke 4-5.
    # A busy machine adds the odd sleep on a lock or a page (3.33 at load 15).
    assert per_s < 3.6, f"the logger woke {per_s:.1f} times a second for 2 samples a second"
