"""sensors.serial_imu on a real pseudo-terminal: exact values, bad frames counted, reopen."""

from __future__ import annotations

import itertools
import time

import pytest

from companion.exec_control.config import ConfigError, load_config
from tests.support.configs import plugin, vehicle_config
from tests.support.pty import Pty
from tests.support.vehicle import wait_for
from tests.unit.sensors.test_vectornav import IMU, crc16, xor8

GOOD = f"$VNIMU,{IMU}*{xor8('VNIMU,' + IMU)}\r\n"
GOOD_CRC = f"$VNIMU,{IMU}*{crc16('VNIMU,' + IMU)}\r\n"
CORRUPT = GOOD.replace("+00.381", "+00.391")  # one digit changed, checksum kept
TRUNCATED = GOOD[:30] + "\r\n"


def imu_vehicle(vehicle_factory, pty: Pty):
    return vehicle_factory(
        vehicle_config("imu", plugin("imu", "sensors.serial_imu", device=pty.link))
    )


@pytest.mark.timeout(60)
def test_samples_are_exact_and_bad_frames_are_counted(vehicle_factory, tmp_path):
    pty = Pty(tmp_path / "ttyImu")
    vehicle = imu_vehicle(vehicle_factory, pty)
    imu = vehicle.bus.queue_reader("sensors/imu")
    mag = vehicle.bus.queue_reader("sensors/mag")
    vehicle.wait_running("imu")
    got, fields = [], []

    def stream() -> bool:  # the port flushes its input when opened: repeat until heard
        pty.write(GOOD + CORRUPT + TRUNCATED + "garbage\r\n" + GOOD_CRC)
        got.extend(imu.take(0.3))
        fields.extend(mag.take(0.1))
        return len(got) >= 2 and len(fields) >= 2

    wait_for(stream, 15, "IMU samples")
    sample = got[0]
    assert (sample.ax_m_s2, sample.ay_m_s2, sample.az_m_s2) == (0.381, -0.154, -9.657)
    assert (sample.gx_rad_s, sample.gy_rad_s, sample.gz_rad_s) == (-0.005683, 0.002143, -0.001459)
    assert sample.temp_c == 21.6
    assert (fields[0].mx_gauss, fields[0].my_gauss, fields[0].mz_gauss) == (-2.0841, 0.6045, 2.8911)
    # Each burst holds two good frames and three bad ones (checksum, truncated, garbage).
    row = wait_for(
        lambda: (
            (r := vehicle.row("imu"))
            and r.frames_ok >= 2
            and 2 * r.frames_bad == 3 * r.frames_ok
            and r
        ),
        5,
        "every frame counted",
    )
    assert row.restarts == 0


@pytest.mark.timeout(60)
def test_the_imu_is_reopened_after_it_vanishes(vehicle_factory, tmp_path):
    link = tmp_path / "ttyImu"
    pty = Pty(link)
    vehicle = imu_vehicle(vehicle_factory, pty)
    imu = vehicle.bus.queue_reader("sensors/imu")
    vehicle.wait_running("imu")
    wait_for(lambda: pty.write(GOOD) or imu.take(0.2), 15, "first samples")
    pty.vanish()
    pty = Pty(link)  # the USB adapter comes back (a new pty behind the same name)
    wait_for(lambda: pty.write(GOOD) or imu.take(0.2), 20, "samples after the reopen")
    assert vehicle.row("imu").restarts == 0
    pty.vanish()


@pytest.mark.timeout(60)
def test_samples_found_together_keep_their_own_times(vehicle_factory, tmp_path):
    """A driver that reads late (a busy board) finds several samples waiting: each gets
    its own time, so the navigator integrates every one of them."""
    pty = Pty(tmp_path / "ttyImu")
    vehicle = imu_vehicle(vehicle_factory, pty)
    imu = vehicle.bus.queue_reader("sensors/imu")
    vehicle.wait_running("imu")
    got: list = []

    def burst() -> bool:  # four samples in one write: the driver finds them together
        pty.write(GOOD * 4)
        got.extend(imu.take(0.3))
        return len(got) >= 8

    wait_for(burst, 15, "IMU samples")
    stamps = [s.t_us for s in got]
    assert stamps == sorted(stamps) and len(set(stamps)) == len(stamps), stamps
    # No more than the configured period (40 Hz: 25 ms) apart within a burst.
    gaps = [b - a for a, b in itertools.pairwise(stamps)]
    assert min(gaps) <= 25_000, gaps


@pytest.mark.timeout(60)
def test_with_wake_hz_every_sample_comes_but_readers_wake_on_its_grid(vehicle_factory, tmp_path):
    # 100 samples a second, readers woken 10 times a second (the navigator's states).
    pty = Pty(tmp_path / "ttyImu")
    config = plugin("imu", "sensors.serial_imu", device=pty.link, rate_hz=100.0, wake_hz=10.0)
    vehicle = vehicle_factory(vehicle_config("imu", config))
    imu = vehicle.bus.queue_reader("sensors/imu")
    vehicle.wait_running("imu")
    wait_for(lambda: pty.write(GOOD) or imu.take(0.05), 15, "the IMU heard")
    imu.take_notifications()
    samples = woken = 0
    for _ in range(100):  # a second of frames, the reader looking every 5 ms
        pty.write(GOOD)
        for _ in range(2):
            time.sleep(0.005)
            woken += imu.take_notifications()
            samples += len(list(imu.drain()))
    samples += len(imu.take(0.5))
    assert samples >= 95, "samples lost"
    assert 5 <= woken <= 20, f"{woken} wake-ups for {samples} samples"


@pytest.mark.timeout(60)
def test_the_magnetometer_and_pressure_come_on_their_own_grid_every_imu_sample_still_comes(
    vehicle_factory, tmp_path
):
    # The sensor sends all three 100 times a second; the navigator fuses a heading at
    # 5 Hz and a height at 10 Hz, so the driver publishes those at aiding_hz (20 Hz).
    pty = Pty(tmp_path / "ttyImu")
    config = plugin("imu", "sensors.serial_imu", device=pty.link, rate_hz=100.0)
    vehicle = vehicle_factory(vehicle_config("imu", config))
    imu, mag, baro = (vehicle.bus.queue_reader(f"sensors/{c}") for c in ("imu", "mag", "baro"))
    vehicle.wait_running("imu")
    wait_for(lambda: pty.write(GOOD) or imu.take(0.05), 15, "the IMU heard")
    for reader in (imu, mag, baro):
        list(reader.drain())
    imus, mags, baros = [], [], []
    for _ in range(100):  # a second of frames
        pty.write(GOOD)
        time.sleep(0.01)
        imus += [s.t_us for s in imu.drain()]
        mags += [s.t_us for s in mag.drain()]
        baros += [s.t_us for s in baro.drain()]
    imus += [s.t_us for s in imu.take(0.5)]
    mags += [s.t_us for s in mag.drain()]
    baros += [s.t_us for s in baro.drain()]
    assert len(imus) >= 95, "IMU samples lost"
    span_s = (imus[-1] - imus[0]) / 1e6
    assert 15 * span_s <= len(mags) <= 25 * span_s + 1, (len(mags), span_s)
    assert len(baros) == len(mags)
    # Each one is a reading's own: stamped as the IMU sample it came with.
    assert set(mags) <= set(imus) and set(baros) == set(mags)


@pytest.mark.timeout(60)
def test_a_sentence_handed_over_in_pieces_does_not_wake_the_driver_for_each(
    vehicle_factory, tmp_path
):
    """A USB serial adapter in low-latency mode hands a 115200-baud sentence over a
    millisecond's worth of bytes at a time: the driver waits for the rest of a sentence it
    has begun instead of waking for each of its ten pieces (it did), and misses none."""
    pty = Pty(tmp_path / "ttyImu")
    vehicle = imu_vehicle(vehicle_factory, pty)
    imu = vehicle.bus.queue_reader("sensors/imu")
    stats = vehicle.bus.queue_reader("system/plugin_stats")
    vehicle.wait_running("imu")
    wait_for(lambda: pty.write(GOOD) or imu.take(0.2), 15, "the IMU heard")
    line, piece = GOOD.encode(), 115_200 // 10 // 1000  # 11 bytes: a millisecond of line
    pieces = [line[i : i + piece] for i in range(0, len(line), piece)]
    assert len(pieces) >= 8

    def counters_after(t: float):  # the driver's first counters sent after monotonic t
        rows = [r for r in stats.take(1.5) if r.name == b"imu" and r.t_us > 0]
        return time.monotonic() > t + 1.0 and rows and rows[-1]

    time.sleep(0.3)  # the warm-up's samples read, and thrown away
    list(imu.drain())
    quiet = time.monotonic()
    first = wait_for(lambda: counters_after(quiet), 10, "the IMU's counters")
    # 40 sentences a second, each piece on the line's schedule: a writer running late
    # (a busy machine) catches up at once, as the line's bytes would have come anyway.
    start, sent, got = time.monotonic(), 120, []
    for n in range(sent):
        for i, part in enumerate(pieces):
            time.sleep(max(0.0, start + n / 40 + i / 1000 - time.monotonic()))
            pty.write(part.decode())
        got += imu.drain()
    got += imu.take(1.0)
    assert len(got) == sent, f"{len(got)} of {sent} sentences"
    done = time.monotonic()
    last = wait_for(lambda: counters_after(done), 10, "the IMU's counters")
    frames, steps = last.frames_ok - first.frames_ok, last.steps - first.steps
    assert frames == sent
    # Woken by its first piece, once more after the wait, then by the last piece or two.
    assert steps <= len(pieces) // 2 * frames, f"{steps} reads, {frames} sentences"


def _imu_steps(stats) -> int | None:
    """The IMU driver's newest step count on system/plugin_stats (once a second), if any."""
    steps = None
    for s in stats.drain():
        if s.name == b"imu":
            steps = int(s.steps)
    return steps


@pytest.mark.timeout(90)
def test_read_on_wake_wakes_the_driver_once_a_state_and_keeps_every_sample(
    vehicle_factory, tmp_path
):
    """read_on_wake: the port holds a navigation period's first sample until its last has
    come (VMIN), so the driver wakes once a state (50 Hz), not once a sample (100 Hz), and
    still publishes every sample, in order, each a period after the one before."""
    pty = Pty(tmp_path / "ttyImu")
    config = plugin(
        "imu", "sensors.serial_imu", device=pty.link, rate_hz=100.0, wake_hz=50.0,
        read_on_wake=True,
    )  # fmt: skip
    vehicle = vehicle_factory(vehicle_config("imu", config))
    imu, stats = (
        vehicle.bus.queue_reader("sensors/imu"),
        vehicle.bus.queue_reader("system/plugin_stats"),
    )
    vehicle.wait_running("imu")
    wait_for(lambda: pty.write(GOOD) or imu.take(0.05), 15, "the IMU heard")
    time.sleep(0.3)
    list(imu.drain())
    before = wait_for(lambda: _imu_steps(stats), 15, "the IMU's counters")
    start, sent, got = time.monotonic(), 200, []
    for n in range(sent):  # 2 s of samples at 100 Hz, on the device's schedule
        time.sleep(max(0.0, start + n / 100 - time.monotonic()))
        pty.write(GOOD)
        got += imu.drain()
    got += imu.take(1.5)  # the last may wait for its partner until the read timeout (1 s)
    assert len(got) == sent, f"{len(got)} of {sent} samples"
    stamps = [s.t_us for s in got]
    gaps = [b - a for a, b in itertools.pairwise(stamps)]
    assert min(gaps) > 0, "two samples stamped alike, or out of order"
    assert sorted(gaps)[len(gaps) // 2] == pytest.approx(10_000, abs=2_000)
    after = wait_for(lambda: _imu_steps(stats), 5, "the IMU's counters")
    steps = after - before
    # Once a state and a second's counters: about 100 reads for 200 samples (200 without).
    assert steps <= 0.65 * sent, f"{steps} reads for {sent} samples"
    # A lone sample whose partner never comes is still read, at the read timeout at worst.
    pty.write(GOOD)
    assert len(imu.take(2.5)) == 1


def test_read_on_wake_without_the_navigators_grid_is_refused(tmp_path):
    config = plugin("imu", "sensors.serial_imu", device="/dev/null", read_on_wake=True)
    path = tmp_path / "imu.toml"
    path.write_text(vehicle_config("imu", config))
    with pytest.raises(ConfigError, match="read_on_wake needs wake_hz and an IMU at least twice"):
        load_config(path)
