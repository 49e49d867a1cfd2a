"""Return flies to the nearest rally point, as ArduPlane and PX4 do: unless home is nearer
(RALLY_INCL_HOME), the point is beyond RALLY_LIMIT_KM, or the fence forbids it; at the
point's own altitude (above home, or above sea level when uploaded so), never under the
floor."""

from __future__ import annotations

import math

from companion.actuators.airframe import load_airframe
from companion.control.commander import Commander
from companion.control.flight.flight_params import control_params, flight_config
from companion.control.flight.mode_targets import mode_target, return_point
from companion.control.mission.fence import Fence
from companion.control.mission.items import MissionItem
from companion.control.mission.rally import RALLY_PARAMS, RallyPoints, choose_return
from companion.geodesy import LocalFrame
from companion.messages import CommandId, FlightMode, NavFlags, NavState, VehicleCommand
from mavlink_dialect import companion as d

HOME = (-37.9105, 145.134, 80.0)
FRAME = LocalFrame(HOME[0], HOME[1])
DEFAULTS = {p.name: p.default for p in RALLY_PARAMS}
FLOOR = HOME[2] + 30.0
CONFIG = flight_config({p.name: p.default for p in control_params(load_airframe("c172p").control)})


def _latlon(north: float, east: float) -> tuple[float, float]:
    return FRAME.latlon(north, east)


def _item(frame: int, command: int, lat: float, lon: float, z: float, p1: float = 0.0, seq=0):
    """A stored item: a rally point, or a fence circle of radius ``p1``."""
    kind = d.MAV_MISSION_TYPE_RALLY if command == d.MAV_CMD_NAV_RALLY_POINT else 1
    return MissionItem(seq, frame, command, 0, 1, p1, 0, 0, 0, round(lat * 1e7),
                       round(lon * 1e7), z, kind)  # fmt: skip


def _rally(*points: tuple[float, float, float], frame: int = d.MAV_FRAME_GLOBAL_RELATIVE_ALT):
    """Rally items at (north m, east m, altitude) from home."""
    return [
        _item(frame, d.MAV_CMD_NAV_RALLY_POINT, *_latlon(n, e), alt, seq=seq)
        for seq, (n, e, alt) in enumerate(points)
    ]


def _circle_fence(radius_m: float) -> Fence:
    inclusion = d.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION
    return Fence.from_items([_item(d.MAV_FRAME_GLOBAL, inclusion, *HOME[:2], 0.0, radius_m)])


def _choose(rally: RallyPoints, north: float, east: float, **params: float):
    return choose_return(rally, _latlon(north, east), HOME, FLOOR, {**DEFAULTS, **params})


def _where(choice) -> tuple[float, float]:
    assert choice.point is not None, choice.text
    n, e = FRAME.ne(choice.point[0], choice.point[1])
    return round(n), round(e)


def test_return_flies_to_the_nearest_rally_point_at_its_height_above_home():
    rally = RallyPoints.from_items(_rally((0, 1500, 60), (2000, 0, 90)), Fence.from_items([]))
    choice = _choose(rally, 0, 1800)  # out east: the eastern point is nearest
    assert _where(choice) == (0, 1500)
    assert math.isclose(choice.point[2], HOME[2] + 60)
    assert choice.text == "Return: to rally point 1, 300 m away"
    assert _where(_choose(rally, 1900, 300)) == (2000, 0)  # out north: the northern one


def test_home_is_chosen_when_it_is_nearer_unless_rally_incl_home_is_off():
    rally = RallyPoints.from_items(_rally((0, 1500, 60)), Fence.from_items([]))
    choice = _choose(rally, 0, 500)  # home 500 m, the rally point 1000 m
    assert choice.point is None
    assert choice.text == "Return: home, nearer than any rally point"
    assert _where(_choose(rally, 0, 500, RALLY_INCL_HOME=0.0)) == (0, 1500)


def test_a_rally_point_beyond_the_limit_is_not_flown_to():
    rally = RallyPoints.from_items(_rally((0, 8000, 60)), Fence.from_items([]))
    far = _choose(rally, 0, 1000, RALLY_INCL_HOME=0.0)  # 7 km to it, over the 5 km limit
    assert far.point is None
    assert "rally point 1 is 7.0 km away, over RALLY_LIMIT_KM" in far.text
    assert _where(_choose(rally, 0, 1000, RALLY_INCL_HOME=0.0, RALLY_LIMIT_KM=0.0)) == (0, 8000)


def test_a_rally_point_the_fence_forbids_is_never_chosen_and_the_operator_is_told():
    fence = _circle_fence(1000.0)
    rally = RallyPoints.from_items(_rally((0, 1500, 60), (0, -800, 60)), fence)
    assert [p.number for p in rally.points] == [2] and rally.forbidden == (1,)
    # Nearer the forbidden one, the aircraft still goes to the one inside the fence.
    assert _where(_choose(rally, 0, 900, RALLY_INCL_HOME=0.0)) == (0, -800)
    only_outside = RallyPoints.from_items(_rally((0, 1500, 60)), fence)
    told = _choose(only_outside, 0, 900, RALLY_INCL_HOME=0.0)
    assert told.point is None and told.text == "Return: home, rally point 1 outside the fence"


def test_an_absolute_altitude_is_kept_and_one_under_the_floor_is_raised_to_it():
    absolute = _rally((0, 1500, HOME[2] + 70), frame=d.MAV_FRAME_GLOBAL_INT)
    choice = _choose(RallyPoints.from_items(absolute, Fence.from_items([])), 0, 1400)
    assert math.isclose(choice.point[2], HOME[2] + 70)
    low = RallyPoints.from_items(_rally((0, 1500, 5)), Fence.from_items([]))
    raised = _choose(low, 0, 1400)
    assert math.isclose(raised.point[2], FLOOR)
    assert raised.text.endswith("at 30 m above home (its own altitude is too low)")


def test_no_rally_point_stored_is_home_as_always_said_nothing():
    choice = _choose(RallyPoints(), 0, 1400)
    assert choice.point is None and choice.text == ""


def _flying_commander(rally: RallyPoints, north: float, east: float) -> Commander:
    c = Commander(lambda: 3, min_height=lambda: 30.0)
    c.rally = rally
    nav = NavState(flags=int(NavFlags.POSITION_VALID))
    nav.lat_deg, nav.lon_deg, nav.alt_msl_m = HOME
    c.on_nav(nav)  # home
    c.on_armed(True)
    nav.lat_deg, nav.lon_deg = _latlon(north, east)
    nav.alt_msl_m = HOME[2] + 100
    c.on_nav(nav)
    return c


def test_the_commander_gives_the_controller_the_rally_point_and_the_controller_flies_to_it():
    rally = RallyPoints.from_items(_rally((0, 1500, 60)), Fence.from_items([]))
    c = _flying_commander(rally, 0, 1200)
    decision = c.handle(VehicleCommand(command=int(CommandId.RETURN_TO_LAUNCH)))
    assert decision is not None and decision.result == 0
    assert c.take_notices() == ["Return: to rally point 1, 300 m away"]
    assert c.take_notices() == []  # said once
    status = c.status(1)
    assert round(status.target_alt_msl_m) == HOME[2] + 60
    assert tuple(round(v) for v in return_point(status, FRAME)) == (0, 1500)
    nav = NavState(alt_msl_m=HOME[2] + 100)
    sp = mode_target(FlightMode.RTL, status, (0.0, 1200.0), nav, (FRAME, HOME[2]), CONFIG)
    assert (round(sp.b[0]), round(sp.b[1])) == (0, 1500)
    assert math.isclose(sp.alt_msl, HOME[2] + 60)


def test_without_a_rally_point_the_controller_returns_home_at_the_return_altitude():
    c = _flying_commander(RallyPoints(), 0, 1200)
    c.handle(VehicleCommand(command=int(CommandId.RETURN_TO_LAUNCH)))
    status = c.status(1)
    assert math.isnan(status.target_lat_deg)
    config = CONFIG
    nav = NavState(alt_msl_m=HOME[2] + 100)
    sp = mode_target(FlightMode.RTL, status, (0.0, 1200.0), nav, (FRAME, HOME[2]), config)
    assert sp.b == (0.0, 0.0) and math.isclose(sp.alt_msl, HOME[2] + config["RTL_ALT_M"])
