"""On the ground only a take-off opens the throttle: every other mode holds idle and trim."""

from __future__ import annotations

import math

import pytest

from companion.actuators.airframe import load_airframe
from companion.control.flight.attitude_modes import Sticks
from companion.control.flight.controller import FlightController
from companion.control.flight.flight_params import control_params, flight_config
from companion.control.mission.plan import load_plan
from companion.messages import FlightMode, NavFlags, NavState, VehicleStatus
from tests.support.vehicle import REPO

HOME = (-37.9105, 145.134, 81.3)
VALID = int(NavFlags.ATTITUDE_VALID | NavFlags.POSITION_VALID | NavFlags.VELOCITY_VALID)


def _controller(items=None) -> FlightController:
    decls = control_params(load_airframe("c172p").control)
    return FlightController(flight_config({p.name: p.default for p in decls}), items)


def _on_runway(t_s: float, flags: int = VALID) -> NavState:
    nav = NavState(t_us=round(t_s * 1e6), flags=flags)
    nav.lat_deg, nav.lon_deg, nav.alt_msl_m = HOME
    nav.yaw_rad = math.pi / 2
    nav.q[0] = 1.0
    return nav


def _status(mode: FlightMode) -> VehicleStatus:
    s = VehicleStatus(mode=int(mode), armed=1, home_valid=1)
    s.home_lat_deg, s.home_lon_deg, s.home_alt_msl_m = HOME
    s.target_lat_deg, s.target_lon_deg, s.target_alt_msl_m = HOME[0] + 0.01, HOME[1], 200.0
    return s


def _outputs(controller: FlightController, mode: FlightMode, flags: int = VALID):
    return [
        controller.step(_on_runway(i * 0.02, flags), _status(mode), i * 0.02) for i in range(200)
    ]


@pytest.mark.parametrize(
    "mode",
    [
        FlightMode.LOITER,
        FlightMode.RTL,
        FlightMode.GUIDED,
        FlightMode.STABILIZED,
        FlightMode.MANUAL,
        FlightMode.ALTITUDE,
        FlightMode.POSITION,
        FlightMode.ACRO,
        FlightMode.RATTITUDE,
    ],
)
@pytest.mark.parametrize("flags", [VALID, VALID | int(NavFlags.DEAD_RECKONING)])
def test_no_mode_but_take_off_opens_the_throttle_on_the_ground(mode, flags):
    for out in _outputs(_controller(), mode, flags):
        assert out.throttle == 0.0
        assert (out.aileron, out.elevator, out.rudder) == (0.0, 0.0, 0.0)  # trim


def test_a_mission_takes_off_with_or_without_its_take_off_item():
    """Without a take-off item (MAVSDK's mission plug-in adds none) the mission used to hold
    idle on the runway, armed and silent, for ever (issue 47.1): now it takes off, a
    take-off as the ground station sees it (take-off phase 1, the roll)."""
    square = load_plan(REPO / "qgc_plans" / "square.plan")[0]
    assert max(o.throttle for o in _outputs(_controller(square), FlightMode.MISSION)) > 0.5
    outs = _outputs(_controller(square[1:]), FlightMode.MISSION)
    assert max(o.throttle for o in outs) > 0.5
    assert all(o.takeoff_phase == 1 and o.mission_seq == 0 for o in outs[1:])


def test_take_off_opens_the_throttle():
    assert max(o.throttle for o in _outputs(_controller(), FlightMode.TAKEOFF)) > 0.5


def test_the_take_off_roll_is_reported_as_a_take_off_and_nothing_else_is():
    """The ground station's landed state (TAKEOFF) comes from this, from the first step."""
    assert all(o.takeoff_phase == 1 for o in _outputs(_controller(), FlightMode.TAKEOFF))
    assert all(o.takeoff_phase == 0 for o in _outputs(_controller(), FlightMode.LOITER))


def test_a_navigator_drifting_upwards_on_the_runway_does_not_make_it_fly():
    controller = _controller()
    outs = []
    for i in range(300):
        nav = _on_runway(i * 0.02)
        nav.alt_msl_m += 0.2 * i  # 60 m of drift while standing still
        outs.append(controller.step(nav, _status(FlightMode.LOITER), i * 0.02))
    assert all(o.throttle == 0.0 and o.landed for o in outs)


@pytest.mark.parametrize("mode", [FlightMode.ALTITUDE, FlightMode.POSITION])
def test_on_the_ground_the_height_holding_modes_leave_the_throttle_to_the_pilot(mode):
    """Altitude and Position would ask the energy controller for flying speed: on the
    wheels the throttle is the pilot's stick, idle when the stick is."""
    controller = _controller()
    for throttle in (0.0, 0.4):
        sticks = Sticks(0.0, 0.0, 0.0, throttle)
        outs = [
            controller.step(_on_runway(i * 0.02), _status(mode), i * 0.02, sticks)
            for i in range(100)
        ]
        assert {out.throttle for out in outs} == {throttle}
