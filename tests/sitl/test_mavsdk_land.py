"""MAVSDK-Python's takeoff_and_land example on the fixed wing: arm, take off, land().

MAVSDK's land() is COMMAND_LONG MAV_CMD_NAV_LAND with no position. The aircraft has no
landing in its mission, so Land flies the landing pattern back onto the runway it took
off from (a loiter down to 50 m, 800 m out, the glide, the flare), and disarms itself
once stopped. Lockstep JSBSim; every wait is on the vehicle's own telemetry.
"""

from __future__ import annotations

import math

import pytest
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.plugins.telemetry import FlightMode, LandedState

from companion.control.flight.landing_pattern import HOME_TOUCHDOWN_M
from companion.geodesy import LocalFrame
from tests.sim.sim_run import with_sim
from tests.sitl.test_mavsdk_actions import _until
from tests.support.mavsdk_flight import ground_station


async def _takeoff_and_land(port: int) -> dict:
    seen: dict = {}
    async with ground_station(port) as system:
        telemetry, action = TelemetryAsync(system), ActionAsync(system)
        home = await _until(telemetry.subscribe_home(), lambda h: h.latitude_deg != 0, "home")
        frame = LocalFrame(home.latitude_deg, home.longitude_deg)
        await _until(telemetry.subscribe_health(), lambda h: h.is_armable, "armable")
        await action.arm()
        await action.takeoff()
        up = await _until(
            telemetry.subscribe_position(), lambda p: p.relative_altitude_m > 40.0, "40 m up"
        )
        seen["runway"] = frame.ne(up.latitude_deg, up.longitude_deg)  # the climb-out's way
        await action.land()  # UNSUPPORTED before: MAVSDK raised ActionError
        seen["mode"] = await _until(
            telemetry.subscribe_flight_mode(), lambda m: m == FlightMode.LAND, "LAND"
        )
        on_ground = LandedState.ON_GROUND
        await _until(telemetry.subscribe_landed_state(), lambda s: s == on_ground, "landed")
        await _until(telemetry.subscribe_armed(), lambda armed: not armed, "disarmed")
        stop = await _until(telemetry.subscribe_position(), lambda p: True, "a position")
        seen["stop"] = frame.ne(stop.latitude_deg, stop.longitude_deg)
        seen["stop_agl"] = stop.relative_altitude_m
    return seen


@pytest.mark.timeout(1200)
def test_mavsdk_land_brings_the_fixed_wing_back_onto_its_runway(tmp_path):
    seen, out, _truth = with_sim(tmp_path, _takeoff_and_land)
    assert seen["mode"] == FlightMode.LAND, out[-2000:]
    # Stopped on the runway line of the take-off, past the touchdown point.
    heading = math.atan2(seen["runway"][1], seen["runway"][0])
    n, e = seen["stop"]
    along = n * math.cos(heading) + e * math.sin(heading)
    across = -n * math.sin(heading) + e * math.cos(heading)
    assert abs(across) < 10.0, (along, across)
    assert HOME_TOUCHDOWN_M - 30.0 < along < HOME_TOUCHDOWN_M + 600.0, (along, across)
    assert abs(seen["stop_agl"]) < 3.0
