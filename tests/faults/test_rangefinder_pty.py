"""sensors.rangefinder on a real pseudo-terminal: TFmini frames come through garbage and bad
checksums, an out-of-range reading is published flagged invalid, a vanished device is
survived."""

from __future__ import annotations

import os

import pytest

from tests.support.configs import plugin, vehicle_config
from tests.support.pty import Pty
from tests.support.tfmini import frame
from tests.support.vehicle import wait_for


@pytest.mark.timeout(120)
def test_range_readings_through_garbage(vehicle_factory, tmp_path):
    pty = Pty(tmp_path / "ttyRange")
    rangefinder = plugin("range", "sensors.rangefinder", device=pty.link)
    vehicle = vehicle_factory(vehicle_config("range", rangefinder))
    readings = vehicle.bus.latest_reader("sensors/range")
    vehicle.wait_running("range")
    bad = bytearray(frame(250))
    bad[8] ^= 0x55

    def seen(distance_m: float, valid: int) -> bool:
        os.write(pty.master, b"\x59garbage" + bytes(bad) + frame(round(distance_m * 100)))
        got = readings.get()
        return got is not None and got.distance_m == distance_m and got.valid == valid

    wait_for(lambda: seen(3.21, 1), 60, "a valid reading")  # a minute, as on a busy machine
    got = readings.get()
    assert (got.min_distance_m, got.max_distance_m, got.ground_clearance_m) == (0.1, 12.0, 0.1)
    assert got.signal_quality == 100
    wait_for(lambda: seen(15.0, 0), 30, "beyond the TFmini's 12 m: flagged, not dropped")
    assert readings.get().signal_quality == 1
    wait_for(lambda: vehicle.row("range").frames_bad >= 1, 30, "the bad checksum counted")
    assert vehicle.row("range").restarts == 0
    pty.vanish()
