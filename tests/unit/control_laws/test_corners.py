"""Corners and straight legs against a point-mass aircraft, with each airframe's tuning.

The aircraft (tests/support/point_mass.py) flies at the airframe's cruise speed with a
roll response as quick as its roll loop gives and the bank limit it is set to; guidance
uses the airframe's L1 period and damping and the turn radius the controller plans
with. A tuning change in an airframe file shows here first, in milliseconds, before any
JSBSim flight.
"""

from __future__ import annotations

import math

import pytest

from companion.actuators.airframe import load_airframe
from companion.control.flight.controller import TURN_BANK_FRACTION
from companion.control.flight.params import control_params
from companion.control.laws.fillet import arc_phase, fillet
from companion.control.laws.l1_guidance import L1Guidance
from companion.geodesy import STANDARD_GRAVITY as G
from tests.support.point_mass import PointMass, cross_track, fly_legs

AIRFRAMES = ("c172p", "J3Cub")
SQUARE = [(0.0, 0.0), (0.0, 3000.0), (-3000.0, 3000.0), (-3000.0, 0.0), (0.0, 0.0)]
# Two 135° turns: out along a diagonal, back along a line that crosses it.
SHARP = [(0.0, 0.0), (0.0, 2500.0), (-2000.0, 500.0), (-2000.0, 3000.0), (0.0, 1000.0)]
STRAIGHT_MARGIN_M = 500.0  # the straight part of a leg, as the tracking score takes it


def setup(
    airframe: str, wind: tuple[float, float] = (0.0, 0.0)
) -> tuple[L1Guidance, PointMass, float]:
    v = {p.name: p.default for p in control_params(load_airframe(airframe).control)}
    cruise, limit = v["AIRSPEED_CRUISE"], math.radians(v["ROLL_LIMIT_DEG"])
    radius = (cruise + math.hypot(*wind)) ** 2 / (G * math.tan(limit * TURN_BANK_FRACTION))
    guidance = L1Guidance(v["NAVL1_PERIOD"], v["NAVL1_DAMPING"], v["NAVL1_XTRACK_I"])
    aircraft = PointMass(airspeed=cruise, bank_limit=limit, wind_ne=wind, east=-300.0)
    aircraft.heading = math.pi / 2
    return guidance, aircraft, radius


def settled_after(track: list[tuple[float, float]], a, b) -> float:  # type: ignore[no-untyped-def]
    """Distance along a→b from which the aircraft stays within 2 m of the line."""
    length = math.dist(a, b)
    rows = [(al, x) for al, x in cross_track(track, a, b) if al < length - STRAIGHT_MARGIN_M]
    off = [al for al, x in rows if abs(x) >= 2.0]
    return max(off, default=0.0)


def straight_worst(
    track: list[tuple[float, float]], a, b, start: float = STRAIGHT_MARGIN_M
) -> float:  # type: ignore[no-untyped-def]
    """Largest cross-track error between ``start`` m past ``a`` and 500 m before ``b``."""
    length = math.dist(a, b)
    rows = cross_track(track, a, b)
    return max(abs(x) for al, x in rows if start < al < length - STRAIGHT_MARGIN_M)


def test_an_arc_is_tangent_to_both_legs():
    f = fillet((0.0, -1000.0), (0.0, 0.0), (1000.0, 0.0), 200.0)  # east, then a left turn north
    assert f is not None and not f.clockwise
    assert f.lead == pytest.approx(200.0)  # R·tan(45°)
    assert f.centre == pytest.approx((200.0, -200.0))
    assert arc_phase(f, (0.0, -300.0)) == 0
    assert arc_phase(f, (50.0, -100.0)) == 1
    assert arc_phase(f, (300.0, 0.0)) == 2
    assert arc_phase(f, (180.0, -20.0), exit_early=30.0) == 2  # the wings level before its end


def test_short_legs_get_a_tighter_arc_that_still_fits():
    f = fillet((0.0, -100.0), (0.0, 0.0), (100.0, 0.0), 200.0)
    assert f is not None and f.lead == pytest.approx(50.0) and f.radius == pytest.approx(50.0)


def test_a_slight_corner_whose_arc_is_shorter_than_the_roll_out_is_not_followed_for_ever():
    """The arc's start and the point to leave it can be passed in one step: then the new
    leg is flown, never the line into the corner continued."""
    guidance, aircraft, radius = setup("J3Cub")
    turn = math.radians(10.0)  # to the left, off a leg flown due east
    points = [
        (0.0, 0.0),
        (0.0, 1000.0),
        (3000.0 * math.sin(turn), 1000.0 + 3000.0 * math.cos(turn)),
    ]
    legs = fly_legs(guidance, aircraft, points, radius)
    assert straight_worst(legs[1], points[1], points[2]) < 0.5


def test_no_arc_for_a_straight_on_corner():
    assert fillet((0.0, -1000.0), (0.0, 0.0), (0.0, 1000.0), 200.0) is None


@pytest.mark.parametrize("airframe", AIRFRAMES)
def test_after_a_right_angle_it_is_on_the_new_leg_within_600_m(airframe: str):
    guidance, aircraft, radius = setup(airframe)
    legs = fly_legs(guidance, aircraft, SQUARE, radius)
    for k in (1, 2, 3):
        a, b = SQUARE[k], SQUARE[k + 1]
        assert settled_after(legs[k], a, b) < 600.0
        assert straight_worst(legs[k], a, b) < 0.5


@pytest.mark.parametrize("wind", [(0.0, 0.0), (0.0, 5.0)], ids=["calm", "wind"])
@pytest.mark.parametrize("airframe", AIRFRAMES)
def test_after_a_135_degree_turn_it_is_on_the_new_leg_before_the_straight_part(
    airframe: str, wind: tuple[float, float]
):
    """The radius is planned for the ground speed downwind, 280 m for a C172 in 5 m/s:
    at that radius a 135° arc would end 2.4 radii (670 m) past the corner, still tens of
    metres off the new line where its straight part starts. Sharp corners are flown
    tighter so the arc ends within 500 m."""
    guidance, aircraft, radius = setup(airframe, wind)
    legs = fly_legs(guidance, aircraft, SHARP, radius)
    for k in (1, 2):
        a, b = SHARP[k], SHARP[k + 1]
        arc = fillet(SHARP[k - 1], a, b, radius)
        assert arc is not None and arc.lead < STRAIGHT_MARGIN_M
        assert settled_after(legs[k], a, b) < STRAIGHT_MARGIN_M
        # The roll-out from 40° of bank still swings the wind's one 1.7 m past the line.
        assert straight_worst(legs[k], a, b) < 2.0
        # Flown within the bank limit: never more than 41° asked of a 45° limit downwind.
        speed = aircraft.airspeed + math.hypot(*wind)
        assert math.atan(speed**2 / (G * arc.radius)) < aircraft.bank_limit - math.radians(3.0)


@pytest.mark.parametrize("airframe", AIRFRAMES)
def test_in_a_5_m_s_wind_the_corners_still_end_on_the_new_leg(airframe: str):
    guidance, aircraft, radius = setup(airframe, wind=(0.0, 5.0))
    legs = fly_legs(guidance, aircraft, SQUARE, radius)
    for k in (1, 2, 3):
        a, b = SQUARE[k], SQUARE[k + 1]
        assert settled_after(legs[k], a, b) < 600.0
        assert straight_worst(legs[k], a, b) < 1.0


def test_the_arc_ends_on_the_new_leg_closer_than_l1_alone():
    """What the arc is for: L1 alone starts turning one L1 distance from the new line."""
    overshoot = {}
    for arcs in (False, True):
        guidance, aircraft, radius = setup("c172p")
        legs = fly_legs(guidance, aircraft, SQUARE, radius, arcs=arcs)
        rows = cross_track(legs[1], SQUARE[1], SQUARE[2])
        overshoot[arcs] = max(-x for _, x in rows)  # the square turns right: overshoot is left
    assert overshoot[True] < 1.0 and overshoot[True] < overshoot[False]
