"""The GPS-velocity yaw estimator (a bank of yaw hypotheses): it finds the heading from a
turn with no magnetometer and no initial guess, and does not claim one it cannot know."""

from __future__ import annotations

import math

import numpy as np
import pytest

from companion.navigation.yaw_gsf import YawGsf

G = 9.80665


def fly(
    gsf: YawGsf,
    seconds: float,
    yaw0: float,
    turn_rad_s: float,
    speed: float = 20.0,
    bank_coordinated: bool = True,
    rng: np.random.Generator | None = None,
) -> float:
    """A flight at constant speed and turn rate: IMU at 50 Hz, GPS velocity at 5 Hz.
    Returns the true yaw at the end."""
    rng = rng or np.random.default_rng(1)
    dt = 0.02
    lateral = speed * turn_rad_s  # the centripetal acceleration
    roll = math.atan2(lateral, G) if bank_coordinated else 0.0
    yaw = yaw0
    for i in range(round(seconds / dt)):
        if bank_coordinated:  # the accelerometer feels only the lift, along the body's -z
            accel = np.array([0.0, 0.0, -math.hypot(G, lateral)])
            gyro = np.array([0.0, turn_rad_s * math.sin(roll), turn_rad_s * math.cos(roll)])
        else:  # a multicopter skidding round: the sideways push is in the body's y
            accel = np.array([0.0, lateral, -G])
            gyro = np.array([0.0, 0.0, turn_rad_s])
        accel = accel + rng.normal(0.0, 0.3, 3)
        gyro = gyro + rng.normal(0.0, 0.005, 3)
        gsf.predict(dt, accel, gyro, roll, 0.0)
        yaw += turn_rad_s * dt
        if i % 10 == 0:
            vn, ve = speed * math.cos(yaw), speed * math.sin(yaw)
            gsf.update(vn + rng.normal(0.0, 0.2), ve + rng.normal(0.0, 0.2), 0.3)
    return yaw


def yaw_error_deg(estimate: float, truth: float) -> float:
    return abs(math.degrees(math.remainder(estimate - truth, math.tau)))


@pytest.mark.parametrize("yaw0_deg", [-170.0, -60.0, 0.0, 95.0, 150.0])
def test_a_turn_finds_the_heading_from_any_start(yaw0_deg):
    gsf = YawGsf()
    truth = fly(gsf, 20.0, math.radians(yaw0_deg), math.radians(10.0))
    found = gsf.heading()
    assert found is not None
    yaw, std = found
    assert yaw_error_deg(yaw, truth) < 5.0
    assert math.degrees(std) < 8.0


def test_a_skidding_multicopter_turn_finds_it_too():
    gsf = YawGsf()
    truth = fly(gsf, 30.0, math.radians(-120.0), math.radians(-25.0), speed=5.0,
                bank_coordinated=False)  # fmt: skip
    yaw, std = gsf.heading() or (math.nan, math.nan)
    assert yaw_error_deg(yaw, truth) < 8.0
    assert math.degrees(std) < 15.0


def test_straight_flight_claims_no_heading():
    """Without acceleration every hypothesis explains GPS equally well: the spread stays."""
    gsf = YawGsf()
    fly(gsf, 20.0, math.radians(40.0), 0.0)
    _, std = gsf.heading() or (math.nan, math.nan)
    assert math.degrees(std) > 45.0


def test_a_heading_learnt_and_then_a_wrong_burst_of_fixes_recovers():
    gsf = YawGsf()
    rng = np.random.default_rng(3)
    fly(gsf, 15.0, 0.3, math.radians(12.0), rng=rng)
    for _ in range(5):  # multipath: five fixes 15 m/s off
        gsf.update(-15.0, 15.0, 0.3)
    truth = fly(gsf, 15.0, 0.3 + math.radians(12.0) * 15.0, math.radians(12.0), rng=rng)
    yaw, _ = gsf.heading() or (math.nan, math.nan)
    assert yaw_error_deg(yaw, truth) < 5.0


def test_nothing_before_the_first_fix_and_garbage_is_ignored():
    gsf = YawGsf()
    assert gsf.heading() is None
    gsf.predict(0.02, np.array([0.0, 0.0, -G]), np.zeros(3), 0.0, 0.0)
    gsf.update(math.nan, 1.0, 0.3)
    assert gsf.heading() is None
    gsf.update(5.0, 0.0, 0.3)
    assert gsf.heading() is not None
