"""A mission flown through MAVSDK as a user's script would: upload a plan, arm, start, wait."""

from __future__ import annotations

import asyncio
import time
from collections.abc import AsyncIterator, Callable
from typing import Any

from mavsdk.asyncio import Configuration, Mavsdk
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.component_type import ComponentType
from mavsdk.plugins.action import ActionError


async def fly_plan(port: int, plan: str, deadline_s: float) -> dict:
    """Fly ``plan`` with the vehicle heard on udpin ``port``; what MAVSDK saw, as a dict."""
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    seen: dict = {"reached": []}
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        system = await mavsdk.first_autopilot(timeout_s=60.0)
        telemetry, action = TelemetryAsync(system), ActionAsync(system)
        mission = MissionRawAsync(system)
        async for _home in telemetry.subscribe_home():  # a position before arming
            break
        data = await mission.import_qgroundcontrol_mission(plan)
        await mission.upload_mission(data.mission_items)
        seen["total"] = len(data.mission_items)
        await action.arm()
        await mission.start_mission()
        stop = time.monotonic() + deadline_s
        while time.monotonic() < stop and not await mission.is_mission_finished():
            await asyncio.sleep(0.5)
        seen["finished"] = await mission.is_mission_finished()
        try:  # disarming in the air drops the aircraft: refused unless forced
            await action.disarm()
            seen["disarm"] = "accepted"
        except ActionError as exc:
            seen["disarm"] = exc.result.name
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
