"""A mission flown through MAVSDK as a user's script would: upload a plan, arm, start, wait."""

from __future__ import annotations

import asyncio
import json
import math
import time
from collections.abc import AsyncIterator, Awaitable, Callable
from contextlib import asynccontextmanager
from dataclasses import dataclass
from typing import Any

from mavsdk.asyncio import Configuration, Mavsdk
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.mavlink_direct import MavlinkDirectAsync
from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.component_type import ComponentType
from mavsdk.plugins.action import ActionError

from companion.actuators.minissc import position_for_pulse, pulse_us
from companion.geodesy import LocalFrame


@dataclass
class PlanSession:
    """A ground station's MAVSDK plug-ins, with a plan uploaded (``items`` of it)."""

    telemetry: TelemetryAsync
    action: ActionAsync
    mission: MissionRawAsync
    items: int = 0
    system: Any = None  # for the plug-ins a test adds (MAVSDK's System: untyped)


@asynccontextmanager
async def ground_station(port: int, connect_s: float = 60.0) -> AsyncIterator[Any]:
    """MAVSDK as a ground station hearing the vehicle on udpin ``port``: the vehicle's
    System once it has been heard."""
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        yield await mavsdk.first_autopilot(timeout_s=connect_s)


@asynccontextmanager
async def plan_uploaded(
    port: int, plan: str, connect_s: float = 60.0
) -> AsyncIterator[PlanSession]:
    """MAVSDK as a ground station hearing the vehicle on udpin ``port``, once the vehicle
    has a home position, says it is armable (its pre-arm checks pass, as a MAVSDK script
    waits for before arming) and ``plan`` is uploaded."""
    async with ground_station(port, connect_s) as system:
        flight = PlanSession(TelemetryAsync(system), ActionAsync(system), MissionRawAsync(system))
        flight.system = system
        async for _home in flight.telemetry.subscribe_home():
            break
        await until(flight.telemetry.subscribe_health(), lambda h: h.is_armable, "armable", 120)
        data = await flight.mission.import_qgroundcontrol_mission(plan)
        await flight.mission.upload_mission(data.mission_items)
        flight.items = len(data.mission_items)
        yield flight


async def mission_finished(mission: MissionRawAsync, deadline_s: float) -> bool:
    """Whether the started mission finished within ``deadline_s`` (asked twice a second)."""
    stop = time.monotonic() + deadline_s
    while time.monotonic() < stop and not await mission.is_mission_finished():
        await asyncio.sleep(0.5)
    return await mission.is_mission_finished()


async def fly_plan(
    port: int,
    plan: str,
    deadline_s: float,
    then: Callable[[PlanSession], Awaitable[Any]] | None = None,
) -> dict:
    """Fly ``plan`` with the vehicle heard on udpin ``port``, and ``then`` (say, wait for
    the Return's circle) once it has finished; what MAVSDK saw, as a dict."""
    seen: dict = {"reached": []}
    async with plan_uploaded(port, plan) as flight:
        seen["total"] = flight.items
        await flight.action.arm()
        await flight.mission.start_mission()
        seen["finished"] = await mission_finished(flight.mission, deadline_s)
        try:  # disarming in the air drops the aircraft: refused unless forced
            await flight.action.disarm()
            seen["disarm"] = "accepted"
        except ActionError as exc:
            seen["disarm"] = exc.result.name
        if then is not None:
            await then(flight)
    return seen


async def until(
    stream: AsyncIterator[Any],
    predicate: Callable[[Any], bool],
    what: str,
    timeout_s: float,
    detail: Callable[[], str] = lambda: "",
) -> Any:
    """The first value of a MAVSDK stream that ``predicate`` accepts, within ``timeout_s``;
    an AssertionError naming ``what`` (and ``detail()``) otherwise."""

    async def first() -> Any:
        async for value in stream:
            if predicate(value):
                return value
        return None

    try:
        return await asyncio.wait_for(first(), timeout_s)
    except TimeoutError:
        raise AssertionError(f"MAVSDK never saw {what}{detail()}") from None


async def payload_worked(
    flight: PlanSession,
    act: Callable[[], Awaitable[Any]],
    output: int,
    pulses_us: tuple[int, int],
    over: tuple[LocalFrame, tuple[float, float]],
) -> dict:
    """Arm, start the mission and ``act()`` at once (a payload command on the runway); then
    wait for the servo card's ``output`` at the first pulse, then at the second (the plan's
    item), as SERVO_OUTPUT_RAW shows them. The mission's current item when the first came
    (``set_before``), and how far the aircraft was from the point ``over`` gives (a frame,
    north and east m) when the second came (``from_point_m``)."""
    raw = MavlinkDirectAsync(flight.system).subscribe_message("SERVO_OUTPUT_RAW")
    field = f"servo{output}_raw"

    def at(pulse: int) -> Callable[[Any], bool]:
        shown = pulse_us(position_for_pulse(pulse))  # as the card's steps put it out
        return lambda m: json.loads(m.fields_json)[field] == shown

    await flight.action.arm()
    await flight.mission.start_mission()
    await act()
    await until(raw, at(pulses_us[0]), f"output {output} at {pulses_us[0]} us", 60)
    progress = flight.mission.subscribe_mission_progress()
    seen = {"set_before": (await anext(aiter(progress))).current}
    await until(raw, at(pulses_us[1]), f"output {output} at {pulses_us[1]} us", 120)
    where = await anext(aiter(flight.telemetry.subscribe_position()))
    frame, point = over
    seen["from_point_m"] = math.dist(frame.ne(where.latitude_deg, where.longitude_deg), point)
    return seen


async def vehicle_seconds(flight: PlanSession, seconds: float) -> None:
    """Wait until ``seconds`` of the vehicle's own clock have passed (GLOBAL_POSITION_INT's
    time since boot): simulated seconds, however fast the simulation runs."""
    positions = MavlinkDirectAsync(flight.system).subscribe_message("GLOBAL_POSITION_INT")
    start = json.loads((await anext(aiter(positions))).fields_json)["time_boot_ms"]
    end_ms = start + seconds * 1000.0

    def passed(m: Any) -> bool:
        return json.loads(m.fields_json)["time_boot_ms"] >= end_ms

    await until(positions, passed, f"{seconds:g} s of the vehicle's clock", 300)


async def circled(
    flight: PlanSession, over: tuple[LocalFrame, tuple[float, float]], radius_m: float, s: float
) -> None:
    """Wait until the aircraft is within ``radius_m`` of the point ``over`` gives (a frame,
    north and east m), then for ``s`` seconds of the vehicle's clock: the simulation's last
    seconds are then spent there."""
    frame, point = over

    def near(p: Any) -> bool:  # a MAVSDK Position
        return math.dist(frame.ne(p.latitude_deg, p.longitude_deg), point) < radius_m

    await until(flight.telemetry.subscribe_position(), near, f"within {radius_m:g} m", 200)
    await vehicle_seconds(flight, s)
