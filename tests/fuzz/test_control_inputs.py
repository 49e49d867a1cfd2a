"""Property tests: any value in any field the flight controller and the commander read.

The link validates what a ground station sends; these drive what arrives on the bus
(nav/state, vehicle/status, the pilot's sticks) with NaN, infinity, huge and negative
values, in process: no exception, surface commands always finite and within their
travel, an unusable input counted, home always a place on Earth.
"""

from __future__ import annotations

import math

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from companion.actuators.airframe import load_airframe
from companion.control.commander import Commander
from companion.control.flight.attitude_modes import Sticks
from companion.control.flight.controller import FlightController
from companion.control.flight.flight_params import control_params, flight_config
from companion.control.mission.plan import load_plan
from companion.messages import NavFlags, NavState, VehicleStatus
from tests.support.vehicle import REPO

HOME = (-37.9105, 145.134, 81.3)
VALID = int(
    NavFlags.ATTITUDE_VALID
    | NavFlags.HEADING_VALID
    | NavFlags.POSITION_VALID
    | NavFlags.VELOCITY_VALID
    | NavFlags.ALTITUDE_VALID
)
HOSTILE = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([math.nan, math.inf, -math.inf, 1e300, -1e300, 3.4e38, 1e9, -1.0, -1e5]),
)
INT64 = st.integers(-(2**63), 2**63 - 1)
UINT32 = st.integers(0, 2**32 - 1)
NAV_FLOATS = [name for name, kind in NavState._fields_ if name != "t_us" and kind is not None]
NAV_SCALARS = [n for n in NAV_FLOATS if not hasattr(getattr(NavState(), n), "__len__")]
NAV_ARRAYS = [n for n in NAV_FLOATS if hasattr(getattr(NavState(), n), "__len__")]
NAV_INTS = ("flags", "gps_rejected", "heading_rejected")
STATUS_FLOATS = [n for n, _ in VehicleStatus._fields_ if n.endswith(("_deg", "_m"))]
FAST = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _good_nav(i: int) -> NavState:
    """Flying north at 25 m/s, 120 m above home, wings level."""
    nav = NavState(t_us=i * 20_000, flags=VALID)
    nav.lat_deg = HOME[0] + i * 25 * 0.02 / 111_000
    nav.lon_deg, nav.alt_msl_m = HOME[1], HOME[2] + 120.0
    nav.vn_m_s = 25.0
    nav.q[0] = 1.0
    return nav


def _good_status(mode: int) -> VehicleStatus:
    s = VehicleStatus(mode=mode, armed=1, home_valid=1)
    s.home_lat_deg, s.home_lon_deg, s.home_alt_msl_m = HOME
    s.target_lat_deg, s.target_lon_deg, s.target_alt_msl_m = math.nan, math.nan, math.nan
    s.target_radius_m = math.nan
    return s


NAV_CHANGES = st.dictionaries(
    st.sampled_from(NAV_SCALARS + NAV_ARRAYS + list(NAV_INTS) + ["t_us"]),
    st.one_of(HOSTILE, INT64),
    max_size=4,
)
STATUS_CHANGES = st.dictionaries(
    st.sampled_from(
        [*STATUS_FLOATS, "mode", "home_valid", "mission_first", "changes", "go_arounds"]
    ),
    st.one_of(HOSTILE, st.integers(-(2**31), 2**32 - 1)),
    max_size=3,
)
STICKS = st.one_of(st.none(), st.builds(Sticks, HOSTILE, HOSTILE, HOSTILE, HOSTILE))
STEP = st.tuples(st.booleans(), NAV_CHANGES, STATUS_CHANGES, STICKS)


def _assign(msg, name: str, value) -> None:
    """Put ``value`` into one field as well as its C type lets a sender put it there."""
    current = getattr(msg, name)
    if hasattr(current, "__len__"):
        for i in range(len(current)):
            current[i] = float(value)
    elif isinstance(current, float):
        setattr(msg, name, float(value))
    elif isinstance(value, int):
        setattr(msg, name, value)  # ctypes wraps an integer to the field's width
    # a float for an integer field cannot be sent (the bus carries the C struct)


def _controller() -> FlightController:
    decls = control_params(load_airframe("c172p").control)
    mission = load_plan(REPO / "qgc_plans" / "square.plan")[0]
    return FlightController(flight_config({p.name: p.default for p in decls}), mission)


def _assert_within_travel(out) -> None:
    for value in (out.aileron, out.elevator, out.rudder):
        assert math.isfinite(value) and -1.0 <= value <= 1.0
    for value in (out.throttle, out.flaps, out.brakes):
        assert math.isfinite(value) and 0.0 <= value <= 1.0
    assert math.isfinite(out.airspeed)


@FAST
@given(mode=st.integers(0, 9), steps=st.lists(STEP, min_size=1, max_size=25))
def test_the_controller_never_raises_and_its_surfaces_stay_within_travel(mode, steps):
    controller = _controller()
    for i in range(5):  # airborne and flying before anything hostile arrives
        controller.step(_good_nav(i), _good_status(4), i * 0.02)
    for i, (hostile, nav_changes, status_changes, sticks) in enumerate(steps, start=5):
        nav, status = _good_nav(i), _good_status(mode)
        if hostile:
            for name, value in nav_changes.items():
                _assign(nav, name, value)
            for name, value in status_changes.items():
                _assign(status, name, value)
        rejected = controller.rejected
        out = controller.step(nav, status, nav.t_us / 1e6, sticks)
        _assert_within_travel(out)
        if sticks is None and not hostile and mode <= 8:
            assert controller.rejected == rejected  # good input is flown, not counted
    out = controller.step(_good_nav(99), _good_status(4), 99 * 0.02)  # and still flies
    _assert_within_travel(out)


def test_an_infinite_heading_or_a_nan_roll_keeps_the_last_good_output():
    controller = _controller()
    for i in range(5):
        good = controller.step(_good_nav(i), _good_status(4), i * 0.02)
    for name, value in (("yaw_rad", math.inf), ("roll_rad", math.inf), ("roll_rad", math.nan)):
        nav = _good_nav(5)
        setattr(nav, name, value)
        out = controller.step(nav, _good_status(4), 0.1)
        assert (out.aileron, out.elevator, out.throttle) == (
            good.aileron,
            good.elevator,
            good.throttle,
        )
    assert controller.rejected == 3


def test_a_navigator_without_body_rates_is_flown_without_damping():
    """gps_compass has no gyro and publishes NaN rates: "not measured", not a broken input."""
    controller = _controller()
    for i in range(5):
        nav = _good_nav(i)
        nav.roll_rate_rad_s = nav.pitch_rate_rad_s = nav.yaw_rate_rad_s = math.nan
        out = controller.step(nav, _good_status(4), i * 0.02)
        _assert_within_travel(out)
    assert controller.rejected == 0


@FAST
@given(navs=st.lists(st.tuples(NAV_CHANGES, st.booleans(), st.booleans()), min_size=1, max_size=20))
def test_the_commander_never_takes_what_is_not_a_place_as_home(navs):
    commander = Commander(lambda: 3)
    for i, (changes, valid, arm) in enumerate(navs):
        nav = _good_nav(i)
        for name, value in changes.items():
            _assign(nav, name, value)
        if valid:
            nav.flags |= NavFlags.POSITION_VALID
        commander.on_nav(nav)
        commander.on_armed(arm)
        for place in (commander.home, commander.position):
            if place is not None:
                lat, lon, alt = place
                assert abs(lat) <= 90 and abs(lon) <= 180 and math.isfinite(alt)
        status = commander.status(nav.t_us)
        assert not math.isinf(status.home_lat_deg) and not math.isinf(status.home_alt_msl_m)


def test_an_infinite_latitude_is_counted_and_not_taken_as_home():
    commander = Commander(lambda: 0)
    nav = _good_nav(0)
    nav.lat_deg = math.inf
    assert commander.on_nav(nav) is False
    assert commander.home is None and commander.rejected_nav == 1
    assert commander.on_nav(_good_nav(1)) is True
    assert commander.home is not None and math.isfinite(commander.home[0])
