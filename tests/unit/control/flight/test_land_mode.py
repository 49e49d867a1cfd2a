"""PX4's Land mode on this fixed wing: the mission's landing from its DO_LAND_START, as
ArduPlane's DO_LAND_START jump and RTL_AUTOLAND 2 fly it; refused without one."""

from __future__ import annotations

import math

from companion.control.commander import Commander
from companion.control.flight.landing_flight import land_start
from companion.control.mission.plan import checked_plan
from companion.messages import (
    CommandId,
    CommandResult,
    FlightMode,
    NavFlags,
    NavState,
    VehicleCommand,
)
from tests.support.vehicle import REPO
from tests.unit.control.flight.test_ground_safety import HOME, VALID, _controller, _status

LANDING_PLAN = REPO / "benchmarks" / "plans" / "land_east.plan"


def _set_land(c: Commander):
    cmd = VehicleCommand(command=int(CommandId.SET_MODE))
    cmd.param[0] = float(FlightMode.LAND)
    decision = c.handle(cmd)
    assert decision is not None
    return decision


def test_land_is_refused_without_a_landing_in_the_mission_and_accepted_with_one():
    lands = False
    c = Commander(lambda: 5, lambda: lands)
    refused = _set_land(c)
    assert refused.result == CommandResult.DENIED
    assert "DO_LAND_START" in refused.reason
    assert c.mode != FlightMode.LAND
    lands = True
    assert _set_land(c).result == CommandResult.ACCEPTED
    assert c.mode == FlightMode.LAND


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


def test_land_without_a_landing_in_the_mission_circles_where_it_is():
    """Only if the mission changed after Land was accepted: the commander refuses it."""
    controller = _controller(checked_plan(REPO / "qgc_plans" / "square.plan")[0])
    for i in range(50):
        out = controller.step(_in_the_air(i * 0.02), _status(FlightMode.LAND), i * 0.02)
    assert controller.executor is None and out.land_phase == 0
