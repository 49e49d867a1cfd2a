"""MAVSDK (the native 4.x binding, in-process) as a real client of the vehicle."""

from __future__ import annotations

import asyncio

import pytest
from mavsdk.asyncio import Configuration, Mavsdk
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.failure import FailureAsync
from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync
from mavsdk.asyncio.plugins.param import ParamAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.component_type import ComponentType
from mavsdk.plugins.failure import FailureError, FailureType, FailureUnit
from mavsdk.plugins.mission_raw import MissionItem

from tests.protocol.mav_client import free_udp_port
from tests.support.configs import client_vehicle
from tests.support.plugins import FakeNav
from tests.support.vehicle import wait_for


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
        # As a MAVSDK user does: arm once the vehicle says it is armable (its pre-arm checks
        # pass: the GPS plug-in, started beside the link, may not have a fix yet).
        armable = _first(telemetry.subscribe_health(), lambda health: health.is_armable)
        await asyncio.wait_for(armable, 30)
        await action.arm()
        armed = await asyncio.wait_for(_first(telemetry.subscribe_armed(), bool), 5)
        flight_pid = vehicle.row("flight").pid
        await action.disarm()
        await asyncio.sleep(1.5)
        return {"position": position, "armed": armed, "flight_pid": flight_pid}


@pytest.mark.timeout(120)
def test_mavsdk_sees_position_and_can_arm_and_disarm(vehicle_factory, tmp_path):
    port = free_udp_port()
    vehicle = vehicle_factory(client_vehicle(f"udpout://127.0.0.1:{port}", tmp_path))
    vehicle.wait_running("link")
    result = asyncio.run(_session(port, vehicle))
    pos = result["position"]
    assert pos.latitude_deg == pytest.approx(FakeNav.LAT, abs=1e-7)
    assert pos.longitude_deg == pytest.approx(FakeNav.LON, abs=1e-7)
    assert pos.absolute_altitude_m == pytest.approx(FakeNav.ALT, abs=0.01)
    assert result["armed"] is True
    assert result["flight_pid"] > 0, "arming started the flight group"
    wait_for(lambda: vehicle.row("flight").pid == 0, 5, "disarm stopped the flight group")


def _raw_items(count: int) -> list[MissionItem]:
    items = []
    for seq in range(count):
        items.append(
            MissionItem(
                seq,
                6,
                16,
                int(seq == 0),
                1,
                0.0,
                10.0,
                0.0,
                float("nan"),
                -379105000 + seq * 900,
                1451340000 + (seq % 7) * 900,
                100.0,
                0,
            )
        )
    return items


async def _mission_session(port: int, items: list[MissionItem]) -> list:
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        system = await mavsdk.first_autopilot(timeout_s=15.0)
        mission = MissionRawAsync(system)
        await mission.upload_mission(items)
        return await mission.download_mission()


@pytest.mark.timeout(120)
def test_mavsdk_mission_raw_upload_and_download(vehicle_factory, tmp_path):
    port = free_udp_port()
    vehicle = vehicle_factory(client_vehicle(f"udpout://127.0.0.1:{port}", tmp_path))
    vehicle.wait_running("link")
    items = _raw_items(50)
    got = asyncio.run(_mission_session(port, items))
    assert [(i.seq, i.command, i.x, i.y) for i in got] == [
        (i.seq, i.command, i.x, i.y) for i in items
    ]
    assert (tmp_path / "missions" / "mission.json").exists()


async def _import_and_upload(port: int, plan: str) -> tuple[int, int, int, int]:
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        system = await mavsdk.first_autopilot(timeout_s=15.0)
        mission = MissionRawAsync(system)
        data = await mission.import_qgroundcontrol_mission(plan)
        await mission.upload_mission(data.mission_items)
        if data.geofence_items:
            await mission.upload_geofence(data.geofence_items)
        if data.rally_items:
            await mission.upload_rally_points(data.rally_items)
        back = await mission.download_mission()
        return len(data.mission_items), len(back), len(data.geofence_items), len(data.rally_items)


@pytest.mark.timeout(120)
def test_mavsdk_imports_the_shipped_square_plan_and_uploads_it(vehicle_factory, tmp_path):
    from tests.support.vehicle import REPO

    port = free_udp_port()
    vehicle = vehicle_factory(client_vehicle(f"udpout://127.0.0.1:{port}", tmp_path))
    vehicle.wait_running("link")
    plan = str(REPO / "qgc_plans" / "square.plan")
    sent, back, fence, rally = asyncio.run(_import_and_upload(port, plan))
    assert sent == back >= 6
    assert (fence, rally) == (4, 1)
    stored = tmp_path / "missions"
    assert (stored / "fence.json").exists() and (stored / "rally.json").exists()


async def _mode_session(port: int, status) -> dict:
    from mavsdk.plugins.telemetry import FlightMode

    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    seen: dict = {}
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        system = await mavsdk.first_autopilot(timeout_s=15.0)
        telemetry, action = TelemetryAsync(system), ActionAsync(system)
        mission = MissionRawAsync(system)

        async def mode_becomes(mode):
            return await asyncio.wait_for(_first(telemetry.subscribe_flight_mode(), mode.__eq__), 5)

        known = FlightMode.UNKNOWN.__ne__  # until the link has heard the commander
        seen["initial"] = await asyncio.wait_for(
            _first(telemetry.subscribe_flight_mode(), known), 10
        )
        await mission.upload_mission(_raw_items(5))
        await action.arm()
        await mission.start_mission()
        seen["mission"] = await mode_becomes(FlightMode.MISSION)
        await action.return_to_launch()
        seen["rtl"] = await mode_becomes(FlightMode.RETURN_TO_LAUNCH)
        await action.goto_location(-37.9, 145.12, 150.0, float("nan"))
        # Guided is PX4's first external mode: MAVSDK's enumeration has no name for it.
        seen["goto"] = await mode_becomes(FlightMode.UNKNOWN)
        seen["target"] = status.get()
        await action.hold()
        seen["hold"] = await mode_becomes(FlightMode.HOLD)
        await action.disarm()
    return seen


@pytest.mark.timeout(120)
def test_mavsdk_flight_modes_start_mission_return_and_go_to(vehicle_factory, tmp_path):
    from mavsdk.plugins.telemetry import FlightMode

    from companion.messages import FlightMode as Mode

    port = free_udp_port()
    vehicle = vehicle_factory(client_vehicle(f"udpout://127.0.0.1:{port}", tmp_path))
    status = vehicle.bus.latest_reader("vehicle/status")
    wait_for(status.get, 60, "the commander up")
    # Return needs home, from the navigator's first solution: later on a busy machine.
    wait_for(lambda: status.get().home_valid, 60, "home from the first solution")
    seen = asyncio.run(_mode_session(port, status))
    assert seen["initial"] == FlightMode.HOLD  # a fixed wing without a pilot circles
    assert seen["mission"] == FlightMode.MISSION
    assert seen["rtl"] == FlightMode.RETURN_TO_LAUNCH
    assert seen["hold"] == FlightMode.HOLD  # our Loiter, PX4's Hold
    status = seen["target"]
    assert status.mode == Mode.GUIDED
    assert (status.target_lat_deg, status.target_lon_deg) == pytest.approx((-37.9, 145.12))
    assert status.target_alt_msl_m == pytest.approx(150.0)


async def _failure_session(port: int) -> list[str]:
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    results = []
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        system = await mavsdk.first_autopilot(timeout_s=15.0)
        failure, param = FailureAsync(system), ParamAsync(system)
        for enabled in (0.0, 1.0):
            await param.set_param_float("SYS_FAILURE_EN", enabled)
            try:
                await failure.inject(FailureUnit.SENSOR_GPS, FailureType.OFF, 0)
                results.append("SUCCESS")
            except FailureError as exc:
                results.append(exc.result.name)
    return results


@pytest.mark.timeout(120)
def test_mavsdk_failure_injection_is_refused_off_and_outside_the_simulator(
    vehicle_factory, tmp_path
):
    # This vehicle runs on the hardware clock: even with SYS_FAILURE_EN set there is no
    # simulator to fail a device in (tests/sitl/test_failsafes.py injects in one).
    port = free_udp_port()
    vehicle = vehicle_factory(client_vehicle(f"udpout://127.0.0.1:{port}", tmp_path))
    vehicle.wait_running("link")
    assert asyncio.run(_failure_session(port)) == ["DENIED", "UNSUPPORTED"]
