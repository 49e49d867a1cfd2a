"""Standing still on the ground measures the yaw-rate bias (a zero angular rate update):
a magnetometer that wanders by degrees as the motors spin up must not teach the filter a
bias the gyro does not have; a hovering aircraft is not taken for a still one."""

from __future__ import annotations

import math

import numpy as np

from companion.messages import GpsFix, Imu, Magnetometer
from companion.navigation.earth_field import wmm_field
from companion.navigation.ins_ekf import InsEkf, InsEkfConfig
from companion.navigation.ins_still import StillDetector

G = 9.80665
LAT, LON = 47.4, 8.5
BIAS_Z = math.radians(0.3)  # rad/s
HEADING = math.radians(30.0)


def samples(seconds: float, rocking_rad_s: float = 0.0, seed: int = 2):
    """A vehicle standing level at HEADING: IMU 100 Hz, GPS 5 Hz, magnetometer 10 Hz whose
    heading wanders by ±4° over seven seconds (motor currents)."""
    rng = np.random.default_rng(seed)
    field = wmm_field(LAT, LON).ned()
    for i in range(round(seconds * 100)):
        t = i / 100
        t_us = round(t * 1e6)
        rock = rocking_rad_s * math.sin(math.tau * 1.3 * t)
        gx, gy, gz = rng.normal(0.0, 0.002, 3) + np.array((rock, -rock, BIAS_Z))
        ax, ay, az = rng.normal(0.0, 0.05, 3) + np.array((0.0, 0.0, -G))
        yield Imu(t_us, ax, ay, az, gx, gy, gz, math.nan)
        if i % 20 == 0:
            yield GpsFix(t_us=t_us, lat_deg=LAT, lon_deg=LON, alt_msl_m=400.0, vn_m_s=0.0,
                         ve_m_s=0.0, vd_m_s=0.0, eph_m=1.0, epv_m=2.0, fix_type=3)  # fmt: skip
        if i % 10 == 0:
            seen = HEADING + math.radians(4.0) * math.sin(math.tau * t / 7.0)
            c, s = math.cos(seen), math.sin(seen)
            yield Magnetometer(t_us, c * field[0] + s * field[1], -s * field[0] + c * field[1],
                               field[2])  # fmt: skip


def run(config: InsEkfConfig, rocking_rad_s: float = 0.0) -> InsEkf:
    nav = InsEkf(config)
    for sample in samples(40.0, rocking_rad_s):
        if isinstance(sample, Imu):
            nav.on_imu(sample)
        elif isinstance(sample, GpsFix):
            nav.on_gps(sample)
        else:
            nav.on_mag(sample)
    return nav


def test_standing_still_measures_the_yaw_rate_bias_despite_a_wandering_magnetometer():
    still = run(InsEkfConfig())
    never = run(InsEkfConfig(still_window_s=1e6))  # a window that never closes
    error = abs(math.degrees(still.bg[2] - BIAS_Z))
    error_without = abs(math.degrees(never.bg[2] - BIAS_Z))
    assert still.still_updates > 20
    assert error < 0.003  # deg/s
    assert error_without > 3 * error  # the magnetometer's wander pulled it about


def test_a_rocking_hover_is_not_taken_for_standing_still():
    nav = run(InsEkfConfig(), rocking_rad_s=math.radians(5.0))
    assert nav.aligned
    assert nav.still_updates == 0


def test_the_detector_needs_a_still_window_and_a_known_low_ground_speed():
    rng = np.random.default_rng(4)

    def window(speed: float, gyro_spread: float) -> list:
        detector = StillDetector(1.0)
        found = []
        for i in range(101):
            gyro = rng.normal(0.0, gyro_spread, 3) + np.array((0.01, -0.02, 0.005))
            accel = rng.normal(0.0, 0.05, 3) + np.array((0.0, 0.0, -G))
            result = detector.add(i * 10_000, tuple(accel), tuple(gyro), speed)
            if result is not None:
                found.append(result)
        return found

    ((mean, variance),) = window(0.1, 0.003)
    assert np.allclose(mean, (0.01, -0.02, 0.005), atol=0.002)
    assert 0.0 < variance < math.radians(0.1) ** 2
    assert window(3.0, 0.003) == []  # moving
    assert window(math.nan, 0.003) == []  # GPS silent: not known to be still
    assert window(0.1, math.radians(4.0)) == []  # a hovering airframe's rocking
