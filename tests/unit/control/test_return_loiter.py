"""A return home ends circling at the loiter altitude (RTL_LOITER_ALT_M, which PX4's
RTL_DESCEND_ALT on QGroundControl's Safety page sets): flown home at the return altitude,
descended to on arrival, never climbed to; a rally point keeps its own altitude."""

from __future__ import annotations

import math

from companion.control.flight.flight_params import control_params, flight_config
from companion.control.flight.mode_targets import arrive, loiter_alt, mode_target
from companion.control.mission.setpoint import Kind
from companion.geodesy import LocalFrame
from companion.link.px4_compat import PX4_PARAMS, vehicle_facts
from companion.messages import FlightMode, NavState, VehicleStatus
from companion.params import ParamStore

HOME = (-37.9105, 145.134, 80.0)
FRAME = LocalFrame(HOME[0], HOME[1])
FAR_OUT = (0.0, 2000.0)  # north, east of home (m)


def _config(**px4_names: float):
    """The flight parameters after a ground station wrote ``px4_names``."""
    store = ParamStore(vehicle_facts((*control_params({}), *PX4_PARAMS), 1, {}))
    for name, value in px4_names.items():
        store.set(name, value)
    return store, flight_config({p.name: store.get(p.name) for p in control_params({})})


def _status(rally: tuple[float, float, float] | None = None) -> VehicleStatus:
    status = VehicleStatus(mode=int(FlightMode.RTL))
    status.target_lat_deg = status.target_lon_deg = status.target_alt_msl_m = math.nan
    if rally is not None:
        status.target_lat_deg, status.target_lon_deg = FRAME.latlon(rally[0], rally[1])
        status.target_alt_msl_m = HOME[2] + rally[2]
    return status


def _return(config, status: VehicleStatus):
    """The setpoint Return flies from far out, then the one it flies on arriving."""
    nav = NavState(alt_msl_m=HOME[2] + 120.0)
    sp = mode_target(FlightMode.RTL, status, FAR_OUT, nav, (FRAME, HOME[2]), config)
    top = loiter_alt(status, HOME[2], config)
    there = arrive(sp, FlightMode.RTL, sp.b, nav.alt_msl_m, config, 150.0, top)
    return sp, there


def test_rtl_descend_alt_sets_the_loiter_altitude_the_return_descends_to_at_home():
    store, config = _config(RTL_RETURN_ALT=150.0, RTL_DESCEND_ALT=60.0)
    assert store.get("RTL_ALT_M") == 150.0 and store.get("RTL_LOITER_ALT_M") == 60.0
    on_the_way, at_home = _return(config, _status())
    assert on_the_way.kind == Kind.LINE and math.isclose(on_the_way.alt_msl, HOME[2] + 150.0)
    assert at_home.kind == Kind.CIRCLE and at_home.b == (0.0, 0.0)
    assert math.isclose(at_home.alt_msl, HOME[2] + 60.0)


def test_a_loiter_altitude_above_the_return_altitude_is_not_climbed_to():
    _, config = _config(RTL_RETURN_ALT=80.0, RTL_DESCEND_ALT=200.0)
    _, at_home = _return(config, _status())
    assert at_home.kind == Kind.CIRCLE and math.isclose(at_home.alt_msl, HOME[2] + 80.0)


def test_by_default_the_return_circles_home_at_the_return_altitude():
    store, config = _config()
    assert store.get("RTL_DESCEND_ALT") == store.get("RTL_ALT_M") == 100.0
    _, at_home = _return(config, _status())
    assert math.isclose(at_home.alt_msl, HOME[2] + 100.0)


def test_a_rally_point_is_circled_at_its_own_altitude_not_the_loiter_altitude():
    _, config = _config(RTL_DESCEND_ALT=40.0)
    _, there = _return(config, _status(rally=(0.0, 1500.0, 90.0)))
    assert there.kind == Kind.CIRCLE and math.isclose(there.alt_msl, HOME[2] + 90.0)


def test_a_go_to_keeps_its_own_altitude_on_arrival():
    _, config = _config(RTL_DESCEND_ALT=40.0)
    sp, _ = _return(config, _status())
    there = arrive(sp, FlightMode.GUIDED, sp.b, sp.alt_msl, config, 150.0, HOME[2] + 40.0)
    assert math.isclose(there.alt_msl, sp.alt_msl)
