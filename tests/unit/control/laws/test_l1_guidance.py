"""L1 lateral guidance: signs of the demand on lines and circles, and closed-loop capture.

The closed-loop tests fly a point-mass (unicycle) aircraft at constant speed whose bank
follows the demanded one through a first-order lag, so they check that guidance brings the
aircraft onto the path and holds it there, not just the sign of one demand.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from companion.control.laws.l1_guidance import G, L1Guidance, bank_for

V = 30.0  # m/s
DT = 0.02  # s
BANK_LAG_S = 0.5
BANK_LIMIT = math.radians(35.0)
A, B = (0.0, 0.0), (10_000.0, 0.0)  # a line due north


def vel_on(course_deg: float, speed: float = V) -> tuple[float, float]:
    c = math.radians(course_deg)
    return speed * math.cos(c), speed * math.sin(c)


class Unicycle:
    """(north, east, course) at constant speed; bank lags the demand, turn rate g·tan φ / V."""

    def __init__(self, north: float, east: float, course: float) -> None:
        self.n, self.e, self.course = north, east, course
        self.bank = 0.0
        self.bank_bias = 0.0  # rad the airframe banks beyond what it is asked for

    @property
    def pos(self) -> tuple[float, float]:
        return self.n, self.e

    @property
    def vel(self) -> tuple[float, float]:
        return V * math.cos(self.course), V * math.sin(self.course)

    def step(self, lat_acc: float) -> None:
        bank_dem = bank_for(lat_acc, BANK_LIMIT)
        self.bank += (bank_dem - self.bank) * DT / BANK_LAG_S
        vn, ve = self.vel
        self.course += G * math.tan(self.bank + self.bank_bias) / V * DT
        self.n += vn * DT
        self.e += ve * DT


def fly_line(craft: Unicycle, seconds: float, a=A, b=B) -> tuple[list[float], L1Guidance]:
    """Fly the line for ``seconds``; the cross-track errors the guidance reported."""
    guidance = L1Guidance()
    xtracks = []
    for _ in range(round(seconds / DT)):
        demand = guidance.line(craft.pos, craft.vel, a, b, DT)
        xtracks.append(demand.xtrack)
        craft.step(demand.lat_acc)
    return xtracks, guidance


def fly_circle(
    craft: Unicycle, seconds: float, centre: tuple[float, float], radius: float, cw: bool
) -> list[float]:
    """Fly the circle for ``seconds``; the true radius errors (m) along the way."""
    guidance = L1Guidance()
    errors = []
    for _ in range(round(seconds / DT)):
        demand = guidance.circle(craft.pos, craft.vel, centre, radius, cw)
        craft.step(demand.lat_acc)
        errors.append(math.hypot(craft.n - centre[0], craft.e - centre[1]) - radius)
    return errors


# --- open loop: the sign and size of single demands -------------------------------------


def test_on_the_line_flying_along_it_demands_nothing():
    demand = L1Guidance().line((500.0, 0.0), vel_on(0.0), A, B)
    assert demand.lat_acc == pytest.approx(0.0, abs=1e-9)
    assert demand.xtrack == pytest.approx(0.0, abs=1e-9)
    assert demand.distance == pytest.approx(9_500.0)
    assert demand.target_bearing == pytest.approx(0.0, abs=1e-9)


def test_right_of_the_track_flying_parallel_turns_left():
    demand = L1Guidance().line((500.0, 40.0), vel_on(0.0), A, B)
    assert demand.xtrack == pytest.approx(40.0)
    assert demand.lat_acc < -0.5


def test_left_of_the_track_flying_parallel_turns_right():
    demand = L1Guidance().line((500.0, -40.0), vel_on(0.0), A, B)
    assert demand.xtrack == pytest.approx(-40.0)
    assert demand.lat_acc > 0.5


def test_xtrack_sign_follows_the_line_direction():
    # The same point east of a southbound line is left of it.
    demand = L1Guidance().line((500.0, 40.0), vel_on(180.0), B, A)
    assert demand.xtrack == pytest.approx(-40.0)
    assert demand.lat_acc > 0.5


@pytest.mark.parametrize(
    ("east", "course_deg", "turn"),
    [
        (0.0, 30.0, -1),  # on the line, heading off to the right: turn left
        (0.0, -30.0, +1),
        (20.0, 60.0, -1),  # right of it and heading further right
        (-20.0, -60.0, +1),
    ],
)
def test_heading_away_from_the_line_turns_back(east: float, course_deg: float, turn: int):
    demand = L1Guidance().line((500.0, east), vel_on(course_deg), A, B)
    assert turn * demand.lat_acc > 1.0


def test_demand_grows_with_the_offset_until_it_saturates():
    guidance = L1Guidance()
    accs = [-guidance.line((500.0, e), vel_on(0.0), A, B).lat_acc for e in (5, 20, 60, 120)]
    assert accs == sorted(accs) and accs[0] > 0.0
    # Far off, the intercept is held at 45° to the track (as ArduPlane holds it).
    far = guidance.line((500.0, 5_000.0), vel_on(0.0), A, B)
    l1 = guidance.l1_distance(V)
    expected = -4 * guidance.damping**2 * V * V / l1 * math.sin(math.radians(45.0))
    assert far.lat_acc == pytest.approx(expected, rel=1e-6)


def test_far_behind_the_start_aims_at_the_start():
    pos = (-1_000.0, 500.0)
    to_start = (A[0] - pos[0], A[1] - pos[1])
    course_to_start = math.degrees(math.atan2(to_start[1], to_start[0]))
    guidance = L1Guidance()
    # Pointing straight at the start: nothing to correct, even though that is not the track.
    straight = guidance.line(pos, vel_on(course_to_start), A, B)
    assert straight.lat_acc == pytest.approx(0.0, abs=1e-9)
    assert straight.distance == pytest.approx(math.hypot(*to_start))
    # Pointing to the right of the start turns left, and vice versa.
    assert guidance.line(pos, vel_on(course_to_start + 20.0), A, B).lat_acc < -0.5
    assert guidance.line(pos, vel_on(course_to_start - 20.0), A, B).lat_acc > 0.5


def test_close_behind_the_start_follows_the_line_itself():
    # Within 2·L1 behind the start the line is tracked, not its start point.
    guidance = L1Guidance()
    behind = -0.5 * guidance.l1_distance(V)
    demand = guidance.line((behind, 0.0), vel_on(0.0), A, B)
    assert demand.lat_acc == pytest.approx(0.0, abs=1e-9)
    assert demand.distance == pytest.approx(B[0] - behind)


def test_circle_clockwise_on_the_circle_turns_right_at_v2_over_r():
    radius = 250.0
    # North of the centre heading east: clockwise seen from above.
    demand = L1Guidance().circle((radius, 0.0), vel_on(90.0), (0.0, 0.0), radius, True)
    assert demand.lat_acc == pytest.approx(V * V / radius, rel=1e-6)
    assert demand.xtrack == pytest.approx(0.0, abs=1e-9)
    # Towards the centre, due south (±π).
    assert abs(math.remainder(demand.target_bearing - math.pi, math.tau)) < 1e-9


def test_circle_counter_clockwise_on_the_circle_turns_left():
    radius = 250.0
    demand = L1Guidance().circle((radius, 0.0), vel_on(-90.0), (0.0, 0.0), radius, False)
    assert demand.lat_acc == pytest.approx(-V * V / radius, rel=1e-6)


def test_circle_centre_away_from_origin():
    centre, radius = (1_000.0, -2_000.0), 150.0
    pos = (centre[0], centre[1] - radius)  # west of the centre, heading north: clockwise
    demand = L1Guidance().circle(pos, vel_on(0.0), centre, radius, True)
    assert demand.lat_acc == pytest.approx(V * V / radius, rel=1e-6)


@pytest.mark.parametrize("clockwise", [True, False])
@pytest.mark.parametrize(("course_deg", "turn"), [(45.0, +1), (-45.0, -1)])
def test_far_outside_a_circle_heading_away_turns_towards_it(
    clockwise: bool, course_deg: float, turn: int
):
    # 2 km north of the centre heading north-east (north-west): the centre is behind on the
    # right (left), so the short way round is a right (left) turn, whichever the direction.
    demand = L1Guidance().circle((2_000.0, 0.0), vel_on(course_deg), (0.0, 0.0), 250.0, clockwise)
    assert turn * demand.lat_acc > 1.0
    assert demand.xtrack == pytest.approx(1_750.0)
    assert demand.distance == pytest.approx(1_750.0)


def test_bank_for_is_limited_and_odd():
    limit = math.radians(35.0)
    assert bank_for(0.0, limit) == 0.0
    assert bank_for(G, limit) == pytest.approx(math.radians(35.0))  # 45° wanted
    assert bank_for(G * math.tan(math.radians(20.0)), limit) == pytest.approx(math.radians(20))
    assert bank_for(-3.0, limit) == pytest.approx(-bank_for(3.0, limit))
    assert bank_for(-1e6, limit) == pytest.approx(-limit)


@settings(max_examples=50, deadline=None)
@given(
    north=st.floats(-3_000.0, 3_000.0),
    east=st.floats(-3_000.0, 3_000.0),
    course_deg=st.floats(-180.0, 180.0),
)
def test_line_demand_is_mirror_symmetric(north: float, east: float, course_deg: float):
    # Reflecting the situation across the track reverses the turn and the cross-track error.
    left = L1Guidance().line((north, east), vel_on(course_deg), A, B)
    right = L1Guidance().line((north, -east), vel_on(-course_deg), A, B)
    assert right.lat_acc == pytest.approx(-left.lat_acc, abs=1e-9)
    assert right.xtrack == pytest.approx(-left.xtrack, abs=1e-9)
    assert right.distance == pytest.approx(left.distance)


# --- closed loop ---------------------------------------------------------------------------


@pytest.mark.parametrize("side", [+1, -1])
def test_captures_a_line_from_200_m_at_a_60_degree_intercept(side: int):
    craft = Unicycle(0.0, side * 200.0, math.radians(-side * 60.0))
    xtracks, _ = fly_line(craft, 90.0)
    assert abs(xtracks[-1]) < 1.0
    assert max(abs(x) for x in xtracks[-250:]) < 1.0  # settled, not just passing through
    assert abs(math.remainder(craft.course, math.tau)) < math.radians(1.0)
    # It came from the side it started on and did not swing far past the line.
    assert side * xtracks[0] == pytest.approx(200.0)
    assert max(-side * x for x in xtracks) < 50.0


@pytest.mark.parametrize("clockwise", [True, False])
@pytest.mark.parametrize(
    ("north", "east", "course_deg"),
    [
        (1_000.0, 0.0, 0.0),  # outside, heading away
        (1_000.0, 0.0, 180.0),  # outside, heading at the centre
        (-800.0, 600.0, 60.0),
        (250.0, 0.0, 90.0),  # on the circle, going round clockwise ...
        (250.0, 0.0, -90.0),  # ... or counter-clockwise (one of them the wrong way)
        (0.0, 0.0, 30.0),  # at the centre
    ],
)
def test_captures_a_250_m_circle(clockwise: bool, north: float, east: float, course_deg: float):
    radius, centre = 250.0, (0.0, 0.0)
    craft = Unicycle(north, east, math.radians(course_deg))
    errors = fly_circle(craft, 180.0, centre, radius, clockwise)
    assert abs(errors[-1]) < 3.0
    assert max(abs(e) for e in errors[-500:]) < 3.0
    # ... and goes round the way it was asked to.
    out = (craft.n - centre[0], craft.e - centre[1])
    vn, ve = craft.vel
    going_clockwise = out[0] * ve - out[1] * vn > 0.0
    assert going_clockwise == clockwise


@settings(max_examples=25, deadline=None)
@given(
    offset=st.floats(-500.0, 500.0),
    course_deg=st.floats(-180.0, 180.0),
    along=st.floats(-1_000.0, 2_000.0),
)
def test_converges_onto_the_line_from_anywhere_nearby(
    offset: float, course_deg: float, along: float
):
    craft = Unicycle(along, offset, math.radians(course_deg))
    xtracks, _ = fly_line(craft, 120.0, A, (100_000.0, 0.0))
    assert max(abs(x) for x in xtracks[-250:]) < 1.0
    assert abs(math.remainder(craft.course, math.tau)) < math.radians(2.0)


def test_integrator_trims_out_a_steady_bias():
    # An airframe that flies straight only with 2° of bank held in: plain L1 settles where
    # its capture term cancels the bias, a steady offset that the bounded integrator on the
    # capture angle trims out.
    def settle(xtrack_i: float) -> tuple[list[float], L1Guidance]:
        craft = Unicycle(0.0, 0.0, 0.0)
        craft.bank_bias = math.radians(2.0)
        guidance = L1Guidance(xtrack_i=xtrack_i)
        xtracks = []
        for _ in range(round(300.0 / DT)):
            demand = guidance.line(craft.pos, craft.vel, A, (100_000.0, 0.0), DT)
            xtracks.append(demand.xtrack)
            craft.step(demand.lat_acc)
        return xtracks, guidance

    plain, _ = settle(0.0)
    trimmed, guidance = settle(0.02)
    assert plain[-1] > 1.5  # pushed right, and plain L1 is left there ...
    assert abs(trimmed[-1]) < 0.25 * plain[-1]  # ... which the integrator trims out
    assert -0.1 <= guidance.integ < 0.0


def test_integrator_restarts_on_a_new_line():
    guidance = L1Guidance()
    for _ in range(500):
        guidance.line((500.0, 3.0), vel_on(0.0), A, B, DT)
    assert guidance.integ < 0.0
    guidance.line((500.0, 3.0), vel_on(0.0), A, (20_000.0, 0.0), DT)
    assert abs(guidance.integ) < 1e-3
