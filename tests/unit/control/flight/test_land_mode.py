"""PX4's Land mode on this fixed wing: the mission's landing from its DO_LAND_START, as
ArduPlane's DO_LAND_START jump and RTL_AUTOLAND 2 fly it; without one, back onto the
runway of the take-off (QGroundControl's landing pattern, built from the take-off roll);
refused only before there is a home."""

from __future__ import annotations

import math

import pytest

from companion.control.commander import Commander
from companion.control.flight.landing_flight import land_start
from companion.control.flight.landing_pattern import (
    HOME_APPROACH_AGL_M,
    HOME_APPROACH_M,
    HOME_TOUCHDOWN_M,
)
from companion.control.mission.plan import checked_plan
from companion.messages import (
    CommandId,
    CommandResult,
    FlightMode,
    NavFlags,
    NavState,
    VehicleCommand,
)
from mavlink_dialect import companion as d
from tests.support.vehicle import REPO
from tests.unit.control.flight.test_ground_safety import HOME, VALID, _controller, _status

LANDING_PLAN = REPO / "benchmarks" / "plans" / "land_east.plan"


def _set_land(c: Commander):
    cmd = VehicleCommand(command=int(CommandId.SET_MODE))
    cmd.param[0] = float(FlightMode.LAND)
    decision = c.handle(cmd)
    assert decision is not None
    return decision


def test_land_is_refused_only_with_neither_a_mission_landing_nor_a_home():
    lands = False
    c = Commander(lambda: 5, lambda: lands)
    refused = _set_land(c)
    assert refused.result == CommandResult.DENIED
    assert "no home runway" in refused.reason
    assert c.mode != FlightMode.LAND
    lands = True
    assert _set_land(c).result == CommandResult.ACCEPTED
    assert c.mode == FlightMode.LAND
    lands = False
    c = Commander(lambda: 0, lambda: lands)
    c.home = HOME
    assert _set_land(c).result == CommandResult.ACCEPTED  # the runway at home


def _in_the_air(t_s: float) -> NavState:
    nav = NavState(t_us=round(t_s * 1e6), flags=VALID | int(NavFlags.HEADING_VALID))
    nav.lat_deg, nav.lon_deg, nav.alt_msl_m = HOME[0] + 0.003, HOME[1], HOME[2] + 120.0
    nav.vn_m_s, nav.yaw_rad = 25.0, 0.0
    nav.q[0] = 1.0
    return nav


def test_land_flies_the_mission_from_its_do_land_start():
    items = checked_plan(LANDING_PLAN)[0]
    first = land_start(items)
    assert first is not None and first > 0
    controller = _controller(items)
    status = _status(FlightMode.LAND)
    status.target_lat_deg = status.target_lon_deg = status.target_alt_msl_m = math.nan
    for i in range(100):
        controller.step(_in_the_air(i * 0.02), status, i * 0.02)
    assert controller.executor is not None
    assert controller.executor.current >= first  # on the landing pattern, not circling


def test_land_without_a_landing_in_the_mission_flies_the_pattern_onto_the_runway():
    """Started in the air 330 m north of home (no take-off roll to follow): straight in,
    southwards, loitering down 800 m out, then on the glide to touchdown past home."""
    controller = _controller(checked_plan(REPO / "qgc_plans" / "square.plan")[0])
    for i in range(50):
        out = controller.step(_in_the_air(i * 0.02), _status(FlightMode.LAND), i * 0.02)
    ex = controller.executor
    assert ex is not None and controller.lander.landing_home
    loiter, land = ex.items
    assert loiter.command == d.MAV_CMD_NAV_LOITER_TO_ALT and land.command == d.MAV_CMD_NAV_LAND
    assert loiter.z == HOME_APPROACH_AGL_M
    assert controller.frame is not None
    touchdown = controller.frame.ne(land.x / 1e7, land.y / 1e7)
    assert touchdown == pytest.approx((-HOME_TOUCHDOWN_M, 0.0), abs=0.5)  # south of home
    centre = controller.frame.ne(loiter.x / 1e7, loiter.y / 1e7)
    assert centre[0] == pytest.approx(-HOME_TOUCHDOWN_M + HOME_APPROACH_M, abs=0.5)
    assert out.land_phase == 0  # still circling down to the approach height
    # Another mode: the stored mission is flown afresh, never the pattern's items.
    controller.step(_in_the_air(1.0), _status(FlightMode.MISSION), 1.0)
    assert not controller.lander.landing_home
    assert controller.executor is not None and controller.executor.items[0].seq == 0
    assert len(controller.executor.items) > 2
