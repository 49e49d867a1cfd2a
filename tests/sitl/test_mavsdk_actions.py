"""MAVSDK's Action plug-in flies the simulated aircraft: take-off, go to, hold, return.

Lockstep JSBSim (the testing plug-in's ``sim``, with its ``mavsdk_system`` connected as a
ground station); every wait is on the vehicle's own telemetry (its mode and position), so
a busy machine only makes the test slower.
"""

from __future__ import annotations

import math

import pytest
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.plugins.telemetry import FlightMode

from companion.geodesy import LocalFrame
from tests.support.mavsdk_flight import until

WAIT_S = 240.0  # wall seconds for any one stage: generous, for a loaded machine


async def _until(gen, predicate, what: str):
    return await until(gen, predicate, what, WAIT_S)


async def _flight(system) -> dict:
    seen: dict = {"modes": []}
    telemetry, action = TelemetryAsync(system), ActionAsync(system)
    home = await _until(telemetry.subscribe_home(), lambda h: h.latitude_deg != 0, "home")
    frame = LocalFrame(home.latitude_deg, home.longitude_deg)

    def away(p) -> float:
        return math.hypot(*frame.ne(p.latitude_deg, p.longitude_deg))

    modes = telemetry.subscribe_flight_mode
    await _until(telemetry.subscribe_health(), lambda h: h.is_armable, "armable")
    await action.arm()
    await action.takeoff()
    seen["modes"].append(await _until(modes(), lambda m: m == FlightMode.TAKEOFF, "TAKEOFF"))
    high = await _until(
        telemetry.subscribe_position(), lambda p: p.relative_altitude_m > 40.0, "40 m up"
    )
    seen["takeoff_alt"] = high.relative_altitude_m
    # Go to a point 1.2 km north at 80 m over home: our Guided mode, which MAVSDK's
    # enumeration has no name for (PX4's external-mode slot): anything but Hold.
    north = 1200.0
    lat, lon = frame.latlon(north, 0.0)
    await action.goto_location(lat, lon, home.absolute_altitude_m + 80.0, 0.0)
    seen["goto_mode"] = await _until(
        modes(), lambda m: m not in (FlightMode.TAKEOFF, FlightMode.HOLD), "a go-to mode"
    )

    def near_target(p) -> bool:
        n, e = frame.ne(p.latitude_deg, p.longitude_deg)
        return math.hypot(n - north, e) < 300.0

    await _until(telemetry.subscribe_position(), near_target, "the go-to point")
    await action.hold()
    seen["modes"].append(await _until(modes(), lambda m: m == FlightMode.HOLD, "HOLD"))
    held = await _until(telemetry.subscribe_position(), lambda p: True, "a position")
    seen["held_away"] = away(held)
    await action.return_to_launch()
    rtl = FlightMode.RETURN_TO_LAUNCH
    seen["modes"].append(await _until(modes(), lambda m: m == rtl, "RETURN_TO_LAUNCH"))
    back = await _until(telemetry.subscribe_position(), lambda p: away(p) < 400.0, "home")
    seen["back_away"] = away(back)
    return seen


@pytest.mark.asyncio
@pytest.mark.timeout(900)
@pytest.mark.vehicle(airframe="c172p")
async def test_mavsdk_takeoff_goto_hold_and_return_fly_the_aircraft(sim, mavsdk_system):
    sim.wait_ready()  # as the plug-in's users are told (MAVSDK's is_armable came 20 ms early)
    seen = await _flight(mavsdk_system)
    out = sim.output()
    assert seen["modes"] == [FlightMode.TAKEOFF, FlightMode.HOLD, FlightMode.RETURN_TO_LAUNCH]
    assert seen["goto_mode"] == FlightMode.UNKNOWN, out[-2000:]
    assert seen["takeoff_alt"] > 40.0
    assert seen["held_away"] > 800.0  # it had flown to the go-to point
    assert seen["back_away"] < 400.0
