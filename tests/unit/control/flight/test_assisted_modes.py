"""Altitude, Position, Acro and Rattitude flown from a pilot's sticks, on JSBSim: what a
PX4 pilot expects of each (QGroundControl 4.4 offers them all for a fixed wing)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from companion.control.flight.attitude_modes import Sticks
from companion.geodesy import LocalFrame
from companion.messages import FlightMode
from tests.support.closed_loop import ClosedLoop

HANDS_OFF = Sticks(0.0, 0.0, 0.0, 0.5)  # throttle at half: cruise airspeed
CROSSWIND = (0.0, -6.0, 0.0)  # from the east, across the aircraft's northbound start


def flying(mode: FlightMode, sticks: Sticks, wind=(0.0, 0.0, 0.0)) -> ClosedLoop:
    return ClosedLoop(mode=mode, airborne_agl_m=300.0, sticks=sticks, wind_ned=wind)


def cfg(loop: ClosedLoop, name: str) -> float:
    return loop.controller.config[name]


def across(loop: ClosedLoop, since: int) -> float:
    """How far the aircraft is now from the line it flew along at sample ``since`` (m)."""
    s0, s = loop.samples[since], loop.samples[-1]
    frame = LocalFrame(s0.lat, s0.lon)
    n, e = frame.ne(s.lat, s.lon)
    course = math.atan2(s0.vel_ned[1], s0.vel_ned[0])
    return -n * math.sin(course) + e * math.cos(course)


def test_altitude_holds_the_height_hands_off_and_climbs_at_the_sticks_rate():
    loop = flying(FlightMode.ALTITUDE, HANDS_OFF)
    loop.run(5.0)
    start = loop.samples[-1].alt_msl
    loop.run(30.0)
    alts = np.array([s.alt_msl for s in loop.samples[-1500:]])
    assert np.abs(alts - start).max() < 3.0
    assert max(abs(math.degrees(s.roll)) for s in loop.samples[-500:]) < 3.0
    # Half up on the stick: half the most the energy controller climbs at.
    loop.sticks = Sticks(0.0, 0.5, 0.0, 0.5)
    loop.run(20.0)
    climbed = loop.samples[-1].alt_msl - loop.samples[-500].alt_msl  # over the last 10 s
    assert climbed / 10.0 == pytest.approx(0.5 * cfg(loop, "TECS_CLMB_MAX"), rel=0.25)
    loop.sticks = HANDS_OFF
    released = loop.samples[-1].alt_msl
    loop.run(20.0)
    assert abs(loop.samples[-1].alt_msl - released) < 5.0


def test_altitude_banks_at_the_stick_and_the_throttle_stick_sets_the_airspeed():
    loop = flying(FlightMode.ALTITUDE, Sticks(0.5, 0.0, 0.0, 0.5))
    loop.run(5.0)
    start = loop.samples[-1].alt_msl
    loop.run(15.0)
    roll = np.degrees([s.roll for s in loop.samples[-250:]])
    assert roll.mean() == pytest.approx(0.5 * cfg(loop, "ROLL_LIMIT_DEG"), abs=3.0)
    assert abs(loop.samples[-1].alt_msl - start) < 8.0  # the turn at its height
    loop.sticks = Sticks(0.0, 0.0, 0.0, 1.0)  # full throttle stick: the fastest allowed
    loop.run(40.0)
    speed = np.mean([s.airspeed for s in loop.samples[-250:]])
    assert speed == pytest.approx(cfg(loop, "AIRSPEED_MAX"), abs=3.0)
    loop.sticks = Sticks(0.0, 0.0, 0.0, 0.0)  # idle: the slowest allowed
    loop.run(40.0)
    speed = np.mean([s.airspeed for s in loop.samples[-250:]])
    assert speed == pytest.approx(cfg(loop, "AIRSPEED_MIN"), abs=3.0)


def test_position_holds_the_track_in_a_crosswind_where_altitude_drifts():
    drift = {}
    for mode in (FlightMode.ALTITUDE, FlightMode.POSITION):
        loop = flying(mode, HANDS_OFF, CROSSWIND)
        loop.run(10.0)  # wings level and the track taken
        since = len(loop.samples) - 1
        loop.run(60.0)
        drift[mode] = abs(across(loop, since))
    assert drift[FlightMode.POSITION] < 10.0, drift
    assert drift[FlightMode.ALTITUDE] > 3 * drift[FlightMode.POSITION], drift


def test_acro_rolls_at_the_sticks_rate_and_holds_the_bank_hands_off():
    loop = flying(FlightMode.ACRO, HANDS_OFF)
    loop.run(3.0)
    loop.sticks = Sticks(0.3, 0.0, 0.0, 0.5)
    loop.run(1.0)
    loop.sticks = HANDS_OFF
    loop.run(1.5)  # the roll loop catches up with the attitude the stick moved
    held = math.degrees(loop.samples[-1].roll)
    # One second at 0.3 of the stick: 0.3 of ACRO_ROLL_RATE's degrees.
    assert held == pytest.approx(0.3 * cfg(loop, "ACRO_ROLL_RATE"), abs=5.0)
    loop.run(3.0)
    # Unlike Stabilized, Acro does not level the wings: the bank reached is kept.
    assert math.degrees(loop.samples[-1].roll) == pytest.approx(held, abs=4.0)


def test_rattitude_is_stabilized_near_the_centre_and_acro_beyond():
    loop = flying(FlightMode.RATTITUDE, Sticks(0.4, 0.0, 0.0, 0.5))
    loop.run(8.0)
    roll = np.degrees([s.roll for s in loop.samples[-100:]])
    assert roll.mean() == pytest.approx(0.4 * cfg(loop, "ROLL_LIMIT_DEG"), abs=2.5)
    loop.sticks = Sticks(-1.0, 0.0, 0.0, 0.5)  # beyond RATT_TH: rates, past the bank limit
    loop.run(3.0)
    assert math.degrees(min(s.roll for s in loop.samples[-150:])) < -cfg(loop, "ROLL_LIMIT_DEG")
