"""A controller restarted in flight (its process killed) takes up the leg and its corners.

square.plan is flown from an airborne start by a point-mass aircraft that banks as the
controller asks (coordinated, at the cruise airspeed, no wind): once by one controller,
and once more with that controller replaced by a new one at a point of the flight, told
only what the commander keeps (the mode and the item flown to). Both then fly one track
(0.000 m apart). Before the restored leg, a controller started inside a corner's turn
lead drew a new leg from where it was, got half the lead and an arc it could not fly, and
left the unbroken track by 56 m (first corner) and 119 m (second); started on the first
corner's arc, it forgot the arc (65 m); started 400 m before it, 7.8 m.
"""

from __future__ import annotations

import functools
import math

import pytest

from companion.actuators.airframe import load_airframe
from companion.control.flight.controller import FlightController
from companion.control.flight.flight_params import control_params, flight_config
from companion.control.mission.executor import MissionExecutor
from companion.control.mission.plan import load_plan
from companion.control.mission.resume import resumed_leg, start_mission
from companion.geodesy import STANDARD_GRAVITY as G
from companion.geodesy import LocalFrame
from companion.messages import FlightMode, NavFlags, NavState, VehicleStatus
from tests.support.vehicle import REPO
from tests.unit.control.mission.executor_flying import HOME as HOME_FRAME
from tests.unit.control.mission.executor_flying import HOME_ALT, speed, wp

# The airborne start of companion sim: west of the plan's take-off point, flying east.
HOME = (-37.9105, 145.134, 81.3)
VALID = int(NavFlags.ATTITUDE_VALID | NavFlags.POSITION_VALID | NavFlags.VELOCITY_VALID)
FRAME = LocalFrame(HOME[0], HOME[1])
ITEMS = load_plan(REPO / "qgc_plans" / "square.plan")[0]
DT = 0.02


def _controller() -> FlightController:
    decls = control_params(load_airframe("c172p").control)
    return FlightController(flight_config({p.name: p.default for p in decls}), ITEMS)


def _status(first: int) -> VehicleStatus:
    s = VehicleStatus(mode=int(FlightMode.MISSION), armed=1, home_valid=1, changes=1)
    s.home_lat_deg, s.home_lon_deg, s.home_alt_msl_m = HOME
    s.mission_first = first
    return s


def _nav(t_s: float, pos: tuple[float, float], course: float, roll: float, v: float) -> NavState:
    nav = NavState(t_us=round(t_s * 1e6), flags=VALID)
    nav.lat_deg, nav.lon_deg = FRAME.latlon(*pos)
    nav.alt_msl_m = HOME[2] + 100.0
    nav.vn_m_s, nav.ve_m_s = v * math.cos(course), v * math.sin(course)
    nav.roll_rad, nav.yaw_rad = roll, course
    nav.yaw_rate_rad_s = G * math.tan(roll) / v
    nav.q[0] = 1.0
    return nav


@functools.cache
def _unbroken(duration_s: float) -> list[tuple[float, float]]:
    return _fly(duration_s)[0]


def _fly(duration_s: float, restart=None) -> tuple[list[tuple[float, float]], int]:
    """The track flown (north/east each step) and the step at which the controller was
    replaced: the first step where ``restart(pos, out)`` says so (None: never)."""
    controller = _controller()
    v = controller.config["AIRSPEED_CRUISE"]
    pos, course, roll, seq = (0.0, 0.0), math.pi / 2, 0.0, 0
    track, restarted = [], -1
    for i in range(round(duration_s / DT)):
        t = i * DT
        out = controller.step(_nav(t, pos, course, roll, v), _status(seq), t)
        seq = out.mission_seq  # the commander keeps the item the controller flies to
        if restarted < 0 and restart is not None and restart(pos, out):
            controller, restarted = _controller(), i  # kill -9, started again at once
        roll = out.nav_roll
        course += G * math.tan(roll) / v * DT
        pos = (pos[0] + v * math.cos(course) * DT, pos[1] + v * math.sin(course) * DT)
        track.append(pos)
    return track, restarted


def _place(seq: int) -> tuple[float, float]:
    return FRAME.ne(ITEMS[seq].x / 1e7, ITEMS[seq].y / 1e7)


def _before(seq: int, metres: float):
    """Restart when the aircraft is ``metres`` from waypoint ``seq`` on the leg to it."""

    def due(pos: tuple[float, float], out) -> bool:
        b = _place(seq)
        return math.hypot(b[0] - pos[0], b[1] - pos[1]) < metres

    return due


@pytest.mark.parametrize(
    ("restart", "duration_s"),
    [
        (_before(1, 400.0), 80.0),  # on the first leg, before the corner's lead
        (_before(1, 235.0), 80.0),  # inside the first corner's lead: already turning
        (_before(1, 100.0), 80.0),  # on that corner's arc, flying to the next item
        (_before(2, 150.0), 120.0),  # inside the second corner's lead (waypoint to waypoint)
    ],
    ids=["first-leg", "first-lead", "first-arc", "second-lead"],
)
def test_a_restarted_controller_flies_the_track_an_unbroken_one_flies(restart, duration_s):
    unbroken = _unbroken(duration_s)
    broken, at = _fly(duration_s, restart)
    assert at > 0
    apart = max(math.dist(p, q) for p, q in zip(unbroken[at:], broken[at:], strict=True))
    assert apart < 0.5, f"{apart:.1f} m from the unbroken track"


def test_the_leg_is_taken_up_from_the_previous_waypoint_and_its_corner():
    ex = MissionExecutor(ITEMS, FRAME, HOME[2])
    on_leg = (_place(2)[0] - 300.0, _place(2)[1] + 5.0)  # 300 m before item 2, 5 m off
    leg = resumed_leg(ex, 2, on_leg, 200.0)
    assert leg.start == pytest.approx(_place(1))
    assert leg.corner_from == pytest.approx(_place(0))  # the take-off's place
    far = (on_leg[0], on_leg[1] + 1500.0)  # nowhere near it: from here, drawn back
    leg = resumed_leg(ex, 2, far, 200.0)
    assert leg.corner_from is None
    assert math.dist(leg.start, _place(2)) >= 800.0


def test_after_a_take_off_the_leg_is_its_line_only_when_the_aircraft_is_on_it():
    """The leg after a take-off began where the climb ended: off the line from the take-off's
    place, the line the aircraft flies is taken (through it towards the item)."""
    ex = MissionExecutor(ITEMS, FRAME, HOME[2])
    off = (_place(1)[0] + 100.0, _place(1)[1] - 800.0)  # 100 m north of that line
    leg = resumed_leg(ex, 1, off, 200.0)
    assert leg.corner_from is None
    course = math.atan2(_place(1)[1] - off[1], _place(1)[0] - off[0])
    back = math.atan2(_place(1)[1] - leg.start[1], _place(1)[0] - leg.start[0])
    assert back == pytest.approx(course)
    assert math.dist(leg.start, _place(1)) == pytest.approx(math.hypot(100.0, 800.0))


def test_the_speed_a_do_change_speed_set_is_taken_up():
    items = [wp(0, (0.0, 0.0)), speed(1, 22.0), wp(2, (0.0, 1000.0)), wp(3, (1000.0, 1000.0))]
    ex = MissionExecutor(items, HOME_FRAME, HOME_ALT)
    leg = start_mission(ex, 3, (500.0, 1000.0), HOME_ALT + 100.0, 200.0)
    assert leg is not None and ex.speed == 22.0
    assert leg.start == pytest.approx((0.0, 1000.0), abs=0.1)
    assert leg.corner_from == pytest.approx((0.0, 0.0), abs=0.1)
