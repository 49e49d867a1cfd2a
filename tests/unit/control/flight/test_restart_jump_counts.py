"""A controller restarted in the air goes on with the mission's DO_JUMP counts.

A square flown twice (DO_JUMP back to its first corner, repeat 1), by a point-mass
aircraft that banks as the controller asks. The controller is replaced by a new one (kill
-9, started again) on the second lap, told only what the commander keeps (the mode and
the item flown to) and given the same state directory: the aircraft then leaves the
square after its second lap, as the unbroken flight does. Without the counts on disk the
new controller would count the jump afresh and fly a third lap.
"""

from __future__ import annotations

import math
from pathlib import Path

from companion.actuators.airframe import load_airframe
from companion.control.flight.controller import FlightController
from companion.control.flight.flight_params import control_params, flight_config
from companion.control.mission.jump_counts import JumpCounts
from companion.geodesy import STANDARD_GRAVITY as G
from companion.messages import FlightMode, NavFlags, NavState, VehicleStatus
from tests.unit.control.mission.executor_flying import HOME, HOME_ALT, jump, wp

SIDE = 1500.0
ITEMS = [
    wp(0, (0.0, 0.0)),
    wp(1, (0.0, SIDE)),
    wp(2, (SIDE, SIDE)),
    wp(3, (SIDE, 0.0)),
    jump(4, 1, 1),  # one more lap
    wp(5, (-SIDE, 0.0)),  # then away
]
VALID = int(NavFlags.ATTITUDE_VALID | NavFlags.POSITION_VALID | NavFlags.VELOCITY_VALID)
DT = 0.02


def _controller(state_dir: Path | None) -> FlightController:
    decls = control_params(load_airframe("c172p").control)
    controller = FlightController(flight_config({p.name: p.default for p in decls}), ITEMS)
    controller.jumps = JumpCounts(state_dir)
    controller.jumps.first_solution(landed=False)  # as the plug-in does: in the air
    return controller


def _status(first: int) -> VehicleStatus:
    s = VehicleStatus(mode=int(FlightMode.MISSION), armed=1, home_valid=1, changes=1)
    s.home_lat_deg, s.home_lon_deg = HOME.lat0, HOME.lon0
    s.home_alt_msl_m = HOME_ALT
    s.mission_first = first
    return s


def _nav(t_s: float, pos: tuple[float, float], course: float, roll: float, v: float) -> NavState:
    nav = NavState(t_us=round(t_s * 1e6), flags=VALID)
    nav.lat_deg, nav.lon_deg = HOME.latlon(*pos)
    nav.alt_msl_m = HOME_ALT + 100.0
    nav.vn_m_s, nav.ve_m_s = v * math.cos(course), v * math.sin(course)
    nav.roll_rad, nav.yaw_rad = roll, math.remainder(course, 2 * math.pi)
    nav.yaw_rate_rad_s = G * math.tan(roll) / v
    nav.q[0] = 1.0
    return nav


def _items_flown(state_dir: Path | None, restart_on_lap: int | None) -> list[int]:
    """The items flown to, in order, until item 5 (or a third lap); the controller is
    replaced when it flies to item 2 on lap ``restart_on_lap`` (None: never)."""
    controller = _controller(state_dir)
    v = controller.config["AIRSPEED_CRUISE"]
    pos, course, roll, seq = (-300.0, 0.0), 0.0, 0.0, 0  # flying north towards item 0
    flown: list[int] = []
    for i in range(round(900.0 / DT)):
        out = controller.step(_nav(i * DT, pos, course, roll, v), _status(seq), i * DT)
        if out.mission_seq != seq or not flown:
            flown.append(out.mission_seq)
        seq = out.mission_seq  # the commander keeps the item the controller flies to
        if seq == 5 or flown.count(1) > 2:
            break
        if restart_on_lap is not None and flown.count(2) == restart_on_lap and seq == 2:
            controller, restart_on_lap = _controller(state_dir), None  # kill -9, restarted
        roll = out.nav_roll
        course += G * math.tan(roll) / v * DT
        pos = (pos[0] + v * math.cos(course) * DT, pos[1] + v * math.sin(course) * DT)
    return flown


def test_a_restarted_controller_flies_the_laps_the_plan_asks_for(tmp_path):
    unbroken = _items_flown(tmp_path / "unbroken", None)
    assert unbroken == [0, 1, 2, 3, 1, 2, 3, 5]
    assert _items_flown(tmp_path / "restarted", restart_on_lap=2) == unbroken


def test_without_the_counts_a_restarted_controller_flies_a_lap_too_many():
    """What the counts on disk are for (the state directory left out)."""
    assert _items_flown(None, restart_on_lap=2)[:8] == [0, 1, 2, 3, 1, 2, 3, 1]


def test_counts_are_taken_up_only_after_a_start_in_the_air_for_the_same_mission(tmp_path):
    kept = JumpCounts(tmp_path)
    kept.first_solution(landed=False)
    kept.keep(ITEMS, {4: 1})
    on_ground = JumpCounts(tmp_path)
    on_ground.first_solution(landed=True)  # a new flight: what is on disk is forgotten
    assert on_ground.take_up(ITEMS) == {}
    kept.keep(ITEMS, {4: 2})  # the next jump counted
    other = JumpCounts(tmp_path)
    other.first_solution(landed=False)
    assert other.take_up(ITEMS[:-1]) == {}  # another mission's counts
    again = JumpCounts(tmp_path)
    again.first_solution(landed=False)
    assert again.take_up(ITEMS) == {4: 2}
    assert again.take_up(ITEMS) == {}  # once
    (tmp_path / "jump_counts.json").write_text("{garbage")
    broken = JumpCounts(tmp_path)
    broken.first_solution(landed=False)
    assert broken.take_up(ITEMS) == {}
