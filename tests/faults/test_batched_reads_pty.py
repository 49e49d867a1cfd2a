"""A rangefinder and an RC receiver on real pseudo-terminals, while nothing needs each of
their frames at once (disarmed): they read what piled up a few times a second, and still
put every frame on the bus, in order, each stamped a device period after the last."""

from __future__ import annotations

import os
import threading
import time

import numpy as np
import pytest

from companion.messages import FlightMode, VehicleStatus
from tests.runtime.test_flight_log import voluntary_switches
from tests.support import sbus, tfmini
from tests.support.configs import plugin, vehicle_config
from tests.support.pty import Pty
from tests.support.vehicle import wait_for
from tests.unit.sensors.test_battery_monitor import sentence

FRAMES = 300  # 3 s at 100 Hz
RATE_HZ = 100.0


def _write_every(master: int, frames: list[bytes], period_s: float) -> threading.Thread:
    def run() -> None:
        start = time.monotonic()
        for i, data in enumerate(frames):
            time.sleep(max(0.0, start + i * period_s - time.monotonic()))
            os.write(master, data)

    writer = threading.Thread(target=run, daemon=True)
    writer.start()
    return writer


def _roll_us(i: int) -> int:
    return 1000 + 3 * i  # a different roll pulse in every frame, to tell them apart


@pytest.mark.timeout(240)
def test_disarmed_the_rangefinder_and_receiver_batch_their_reads_and_lose_no_frame(
    vehicle_factory, tmp_path
):
    range_pty, rc_pty = Pty(tmp_path / "ttyRange"), Pty(tmp_path / "ttyRC")
    vehicle = vehicle_factory(
        vehicle_config(
            "batched",
            plugin("range", "sensors.rangefinder", device=range_pty.link),
            plugin("rc", "sensors.rc_input", device=str(rc_pty.link), rate_hz=RATE_HZ),
        )
    )
    # What the commander says on the bench, four times a second: disarmed.
    status = vehicle.bus.writer("vehicle/status")
    done = threading.Event()

    def commander() -> None:
        while not done.wait(0.25):
            status.publish(VehicleStatus(t_us=0, mode=int(FlightMode.MANUAL), armed=0))

    threading.Thread(target=commander, daemon=True).start()
    ranges = vehicle.bus.latest_reader("sensors/range", keep=32)
    sticks = vehicle.bus.latest_reader("sensors/rc", keep=32)
    pids = {name: vehicle.wait_running(name) for name in ("range", "rc")}
    centre = [sbus.us_to_raw(1500)] * 16

    def heard() -> bool:  # a port opened late flushes what was written before
        os.write(rc_pty.master, sbus.frame(centre))
        os.write(range_pty.master, tfmini.frame(50))
        time.sleep(0.05)
        return ranges.get() is not None and sticks.get() is not None

    wait_for(heard, 60, "first frames")
    time.sleep(0.5)
    ranges.drain()  # the warm-up frames
    sticks.drain()

    def rc_frame(i: int) -> bytes:
        return sbus.frame([sbus.us_to_raw(_roll_us(i)), *centre[1:]])

    before = {name: voluntary_switches(pid) for name, pid in pids.items()}
    started = time.monotonic()
    writers = [
        _write_every(range_pty.master, [tfmini.frame(100 + i) for i in range(FRAMES)], 0.01),
        _write_every(rc_pty.master, [rc_frame(i) for i in range(FRAMES)], 0.01),
    ]
    got_range, got_rc = [], []
    while len(got_range) < FRAMES or len(got_rc) < FRAMES:
        assert time.monotonic() - started < 120, f"{len(got_range)}, {len(got_rc)} of {FRAMES}"
        got_range += ranges.drain()
        got_rc += sticks.drain()
        time.sleep(0.02)
    for writer in writers:
        writer.join()
    elapsed = time.monotonic() - started
    woke = {name: (voluntary_switches(pid) - before[name]) / elapsed for name, pid in pids.items()}
    done.set()

    assert [round(r.distance_m * 100) for r in got_range] == [100 + i for i in range(FRAMES)]
    assert [r.channels_us[0] for r in got_rc] == pytest.approx(
        [_roll_us(i) for i in range(FRAMES)], abs=1
    )
    for name, got in (("range", got_range), ("rc", got_rc)):
        gaps = np.diff([m.t_us for m in got])
        assert (gaps > 0).all(), f"{name}: frames stamped alike or out of order"
        # Frames found together are a device period apart, as they were sent.
        assert np.median(gaps) == pytest.approx(1e6 / RATE_HZ, rel=0.05), name
        # 100 frames a second, read in batches of 0.1 s: about 10 reads a second.
        assert woke[name] < 40, f"{name} woke {woke[name]:.0f} times a second for 100 frames"


@pytest.mark.timeout(240)
def test_the_battery_monitor_batches_its_reads_and_counts_every_readings_charge(
    vehicle_factory, tmp_path
):
    """Nothing acts on one reading of the pack, armed or not: it is read twice a second, and
    the charge used still adds up every reading's current, each stamped a period apart."""
    rate_hz, frames, amps = 50.0, 150, 36.0  # 3 s of readings
    pty = Pty(tmp_path / "ttyBattery")
    vehicle = vehicle_factory(
        vehicle_config(
            "batched_battery",
            plugin("battery", "sensors.battery", device=pty.link, rate_hz=rate_hz),
        )
    )
    status = vehicle.bus.writer("vehicle/status")
    done = threading.Event()

    def commander() -> None:  # armed in Mission: the battery is batched even so
        while not done.wait(0.25):
            status.publish(VehicleStatus(t_us=0, mode=int(FlightMode.MISSION), armed=1))

    threading.Thread(target=commander, daemon=True).start()
    packs = vehicle.bus.latest_reader("sensors/battery", keep=64)
    pid = vehicle.wait_running("battery")

    def heard() -> bool:
        os.write(pty.master, sentence("PCBAT,12000,0"))
        time.sleep(0.05)
        return packs.get() is not None

    wait_for(heard, 60, "first reading")
    time.sleep(1.0)
    packs.drain()
    before, started = voluntary_switches(pid), time.monotonic()
    readings = [sentence(f"PCBAT,{12000 - i},{round(amps * 1000)}") for i in range(frames)]
    writer = _write_every(pty.master, readings, 1 / rate_hz)
    got = []
    while len(got) < frames:
        assert time.monotonic() - started < 60, f"{len(got)} of {frames}"
        got += packs.drain()
        time.sleep(0.05)
    writer.join()
    woke = (voluntary_switches(pid) - before) / (time.monotonic() - started)
    done.set()

    gaps = np.diff([b.t_us for b in got])
    assert (gaps > 0).all(), "readings stamped alike or out of order"
    assert np.median(gaps) == pytest.approx(1e6 / rate_hz, rel=0.05)
    # 36 A for the 149 periods between the first and last reading of the run: 29.8 mAh.
    used = got[-1].consumed_mah - got[0].consumed_mah
    assert used == pytest.approx(amps * 1000 * (frames - 1) / rate_hz / 3600, rel=0.02)
    # 50 readings a second, read in batches of 0.5 s: a few reads a second.
    assert woke < 15, f"the battery monitor woke {woke:.0f} times a second for 50 readings"
