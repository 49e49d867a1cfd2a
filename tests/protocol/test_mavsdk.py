"""MAVSDK (the native 4.x binding, in-process) as a real client of the vehicle."""

from __future__ import annotations

import asyncio

import pytest
from mavsdk.asyncio import Configuration, Mavsdk
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.component_type import ComponentType

from tests.protocol.mav_client import free_udp_port
from tests.support.plugins import FakeNav
from tests.support.vehicle import wait_for

VEHICLE = """
[vehicle]
name = "mavsdk"

[[plugins]]
name = "link"
plugin = "link.mavlink"
settings = {{ endpoints = ["udpout://127.0.0.1:{port}"] }}

[[plugins]]
name = "nav"
plugin = "tests.support.plugins:FakeNav"

[[plugins]]
name = "flight"
plugin = "tests.support.plugins:Waiting"
group = "flight"
"""


async def _first(gen, predicate=lambda _v: True):
    async for value in gen:
        if predicate(value):
            return value
    return None


async def _session(port: int, vehicle) -> dict:
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        system = await mavsdk.first_autopilot(timeout_s=15.0)
        assert system is not None, "MAVSDK found no autopilot"
        telemetry, action = TelemetryAsync(system), ActionAsync(system)
        position = await asyncio.wait_for(_first(telemetry.subscribe_position()), 10)
        await action.arm()
        armed = await asyncio.wait_for(_first(telemetry.subscribe_armed(), bool), 5)
        flight_pid = vehicle.row("flight").pid
        await action.disarm()
        await asyncio.sleep(1.5)
        return {"position": position, "armed": armed, "flight_pid": flight_pid}


@pytest.mark.timeout(120)
def test_mavsdk_sees_position_and_can_arm_and_disarm(vehicle_factory):
    port = free_udp_port()
    vehicle = vehicle_factory(VEHICLE.format(port=port))
    vehicle.wait_running("link")
    result = asyncio.run(_session(port, vehicle))
    pos = result["position"]
    assert pos.latitude_deg == pytest.approx(FakeNav.LAT, abs=1e-7)
    assert pos.longitude_deg == pytest.approx(FakeNav.LON, abs=1e-7)
    assert pos.absolute_altitude_m == pytest.approx(FakeNav.ALT, abs=0.01)
    assert result["armed"] is True
    assert result["flight_pid"] > 0, "arming started the flight group"
    wait_for(lambda: vehicle.row("flight").pid == 0, 5, "disarm stopped the flight group")
