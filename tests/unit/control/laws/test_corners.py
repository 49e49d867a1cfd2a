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

import companion.control.laws.fillet as corners
from companion.actuators.airframe import load_airframe
from companion.control.flight.controller import TURN_BANK_FRACTION
from companion.control.flight.flight_params import control_params
from companion.control.laws.fillet import Loop, arc_phase, fillet, loop_phase
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


def _on_arc(arc: corners.Arc, turned: float) -> tuple[float, float]:
    bearing = arc.start + (turned if arc.clockwise else -turned)
    return (
        arc.centre[0] + arc.radius * math.cos(bearing),
        arc.centre[1] + arc.radius * math.sin(bearing),
    )


@pytest.mark.parametrize("turn_deg", [-170.0, -146.0, 125.0, 146.0])
def test_a_sharp_corner_is_a_loop_that_ends_on_the_new_line_at_the_corner(turn_deg: float):
    """Away from the new leg, then round onto it: the arcs meet, the second ends on the
    new line heading along it, within a radius of the corner, and the loop starts no
    earlier than a 120° arc would."""
    course = math.radians(90.0 + turn_deg)  # from a leg flown due east
    nxt = (2000.0 * math.cos(course), 2000.0 * math.sin(course))
    loop = fillet((0.0, -2000.0), (0.0, 0.0), nxt, 200.0)
    assert isinstance(loop, Loop)
    away, onto = loop.arcs
    assert away.clockwise == (turn_deg < 0) and onto.clockwise == (turn_deg > 0)
    assert loop.lead == pytest.approx(200.0 * math.tan(math.radians(60.0)))
    assert _on_arc(away, 0.0) == pytest.approx((0.0, -loop.lead))
    assert _on_arc(away, away.sweep) == pytest.approx(_on_arc(onto, 0.0))
    end = _on_arc(onto, onto.sweep)
    u = loop.u_out
    assert -end[0] * u[1] + end[1] * u[0] == pytest.approx(0.0, abs=1e-6)  # on the new line
    assert end[0] * u[0] + end[1] * u[1] == pytest.approx(loop.exit)  # where it says
    assert abs(loop.exit) < loop.radius
    assert onto.sweep - away.sweep == pytest.approx(math.radians(abs(turn_deg)))
    # The phases: before the loop, on each arc in turn, then on the new leg.
    assert loop_phase(loop, (0.0, -loop.lead - 50.0), 0) == 0
    assert loop_phase(loop, _on_arc(away, 0.1), 0) == 1
    assert loop_phase(loop, _on_arc(onto, 0.1), 1) == 2
    assert loop_phase(loop, _on_arc(onto, onto.sweep - 0.01), 2, exit_early=30.0) == 3


def test_a_corner_of_120_degrees_or_less_is_an_arc():
    course = math.radians(90.0 + 118.0)
    nxt = (2000.0 * math.cos(course), 2000.0 * math.sin(course))
    assert isinstance(fillet((0.0, -2000.0), (0.0, 0.0), nxt, 200.0), corners.Fillet)


@pytest.mark.parametrize("wind", [(0.0, 0.0), (0.0, 5.0)], ids=["calm", "wind"])
@pytest.mark.parametrize("airframe", AIRFRAMES)
def test_after_a_146_degree_corner_the_loop_is_on_the_new_line_by_the_corner(
    airframe: str, wind: tuple[float, float], monkeypatch: pytest.MonkeyPatch
):
    """The jump plan's corner. An arc tangent to both legs ends 3.3 radii down the new
    leg: the C172 in a 5 m/s wind was still on it, hundreds of metres off the line, where
    the leg's straight part starts. The loop leaves it on the line there (its own start
    lies beside the first 300-400 m of the new leg, as the leg into such a corner does)."""
    legs_ne = [(0.0, 0.0), (0.0, 1800.0), (1000.0, 1800.0), (1000.0, 300.0), (0.0, 1800.0)]
    legs_ne.append((1000.0, 1800.0))
    worst = {}
    for loops in (True, False):
        if not loops:
            monkeypatch.setattr(corners, "LOOP_TURN_RAD", math.pi)
        guidance, aircraft, radius = setup(airframe, wind)
        legs = fly_legs(guidance, aircraft, legs_ne, radius)
        a, b = legs_ne[3], legs_ne[4]
        worst[loops] = straight_worst(legs[3], a, b)
    assert worst[True] < 0.5
    assert worst[True] < worst[False]


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
