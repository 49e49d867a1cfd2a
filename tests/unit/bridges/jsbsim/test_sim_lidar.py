"""The simulator's TFmini writer (bridges/jsbsim/device_streams.py) against the vehicle's
codec: the frames the bridge writes are read as the heights it meant."""

from __future__ import annotations

import math

import pytest

from bridges.jsbsim.device_streams import lidar_reading, tfmini_frame
from companion.sensors.tfmini import TfminiDecoder, TfminiFramer


def read(data: bytes):
    framer, dec = TfminiFramer(), TfminiDecoder()
    return [dec.decode(f, 0) for f in framer.feed(data)]


@pytest.mark.parametrize("height", [0.1, 0.5, 3.0, 11.9])
def test_a_height_in_range_is_read_back_level(height):
    (r,) = read(tfmini_frame(*lidar_reading(height, 0.0, 0.0, 0.0)))
    assert r is not None and r.valid and r.distance_m == pytest.approx(height, abs=0.006)


def test_a_banked_lidar_reads_along_its_beam():
    roll = math.radians(15)
    (r,) = read(tfmini_frame(*lidar_reading(4.0, roll, 0.0, 0.0)))
    assert r is not None and r.distance_m == pytest.approx(4.0 / math.cos(roll), abs=0.006)


@pytest.mark.parametrize("height", [12.5, 300.0, 0.02])
def test_out_of_range_is_the_devices_no_reading(height):
    (r,) = read(tfmini_frame(*lidar_reading(height, 0.0, 0.0, 0.0)))
    assert r is not None and not r.valid and r.distance_m == -1.0
