"""MAVSDK's own mission.py and geofence.py call sequences against the simulated aircraft.

Issue 47: mission.py's waypoints carry no take-off item (MAVSDK's mission plug-in adds
none), and the aircraft sat armed in Mission on the runway for good, saying nothing;
geofence.py (MAVSDK-Python 3.15.3, through mavsdk_server) sends, beside its inclusion
polygon, the placeholder circle its API needs (radius 0 at 0,0), and the whole fence was
refused. The MAVSDK library here (4.1) refuses that circle itself before sending it, so
the fence is replayed with pymavlink item by item as mavsdk_server sent it, on a second
link. One lockstep flight (``companion sim --speed max``, c172p): the fence goes up, the
mission as mission.py does (return after the mission on, waypoints with a speed, fly
through), arm, start. The aircraft must say it takes off, take off, fly the first
waypoints, and be turned home by the fence when the plan leaves the polygon. Every wait is
on the vehicle's own telemetry, so a busy machine only makes the test slower.
"""

from __future__ import annotations

import asyncio
import os
import time

import pytest

os.environ.setdefault("MAVLINK20", "1")
from mavsdk.asyncio import Configuration, Mavsdk
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.mission import MissionAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.component_type import ComponentType
from mavsdk.plugins.action import ActionError, ActionResult
from mavsdk.plugins.mission import MissionItem, MissionPlan
from mavsdk.plugins.telemetry import FlightMode
from pymavlink import mavutil

from companion.geodesy import LocalFrame
from companion.navigation.estimate_csv import read_estimate
from mavlink_dialect import companion as d
from tests.protocol.mav_client import free_udp_port
from tests.sim.sim_run import sim_running
from tests.support.mavsdk_flight import until

WAIT_S = 300.0  # wall seconds for any one stage: generous, for a loaded machine
FENCE_M = 2_000.0  # the inclusion square reaches this far north, south, east and west
ALT_M = 60.0  # the waypoints' height over home
# North/east of home: two inside the fence, the third 3 km east, beyond it.
WAYPOINTS = [(1_000.0, 0.0), (1_000.0, 1_000.0), (0.0, 3_000.0)]


async def _until(gen, predicate, what: str, texts: list[str]):
    return await until(gen, predicate, what, WAIT_S, lambda: f"; texts: {texts}")


def _mission_item(frame: LocalFrame, ne: tuple[float, float]) -> MissionItem:
    """As mission.py builds them: a height, a speed, fly-through, nothing else."""
    lat, lon = frame.latlon(*ne)
    return MissionItem(lat, lon, ALT_M, 25.0, True)


def upload_fence_as_mavsdk_server(port: int) -> list[str]:
    """geofence.py's items as mavsdk_server 3.15.3 uploads them: the inclusion polygon's
    four vertices (param1 the count; here round home), then the placeholder circle.
    Returns the texts the vehicle said by the time it acknowledged."""
    conn = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=245)
    try:
        home = conn.recv_match(type="HOME_POSITION", blocking=True, timeout=120)
        assert home is not None, "no home position"
        frame = LocalFrame(home.latitude / 1e7, home.longitude / 1e7)
        m = FENCE_M
        corners = [frame.latlon(n, e) for n, e in ((-m, -m), (m, -m), (m, m), (-m, m))]
        poly, circle = (
            d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION,
            d.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION,
        )
        items = [(poly, 4.0, round(lat * 1e7), round(lon * 1e7)) for lat, lon in corners]
        items.append((circle, 0.0, 0, 0))
        fence = d.MAV_MISSION_TYPE_FENCE
        conn.mav.mission_count_send(1, 1, len(items), fence)
        texts: list[str] = []
        while True:
            msg = conn.recv_match(
                type=["MISSION_REQUEST_INT", "MISSION_ACK", "STATUSTEXT"], blocking=True, timeout=30
            )
            assert msg is not None, f"the fence upload stalled; texts: {texts}"
            if msg.get_type() == "STATUSTEXT":
                texts.append(msg.text)
            elif msg.get_type() == "MISSION_ACK":
                assert msg.type == d.MAV_MISSION_ACCEPTED, (msg, texts)
                break
            else:
                cmd, p1, x, y = items[msg.seq]
                conn.mav.mission_item_int_send(
                    1, 1, msg.seq, d.MAV_FRAME_GLOBAL_INT, cmd, 0, 1, p1, 0, 0, 0, x, y, 0, fence
                )
        end = time.monotonic() + 5.0  # the texts follow the ack
        while time.monotonic() < end and not any("ignored" in t for t in texts):
            msg = conn.recv_match(type="STATUSTEXT", blocking=True, timeout=0.5)
            texts += [msg.text] if msg is not None else []
        return texts
    finally:
        conn.close()


async def _flight(port: int) -> dict:
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    seen: dict = {"texts": []}
    texts: list[str] = seen["texts"]
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        system = await mavsdk.first_autopilot(timeout_s=60.0)
        telemetry, action = TelemetryAsync(system), ActionAsync(system)
        mission = MissionAsync(system)

        async def listen() -> None:
            async for status in telemetry.subscribe_status_text():
                texts.append(status.text)

        listener = asyncio.ensure_future(listen())
        home = await _until(
            telemetry.subscribe_home(), lambda h: h.latitude_deg != 0, "home", texts
        )
        frame = LocalFrame(home.latitude_deg, home.longitude_deg)
        await mission.set_return_to_launch_after_mission(True)
        await mission.upload_mission(MissionPlan([_mission_item(frame, p) for p in WAYPOINTS]))
        await _until(telemetry.subscribe_health(), lambda h: h.is_armable, "armable", texts)
        await action.arm()
        # Armed on the runway: modes that cannot fly from there get a refusal and its reason.
        for ask in (action.return_to_launch, action.hold):
            try:
                await ask()
                seen.setdefault("refused", []).append(None)
            except ActionError as exc:
                seen.setdefault("refused", []).append(exc.result)
        await mission.start_mission()
        up = await _until(
            telemetry.subscribe_position(), lambda p: p.relative_altitude_m > 40.0, "40 m up", texts
        )
        seen["climbed"] = up.relative_altitude_m
        progress = await _until(
            mission.subscribe_mission_progress(), lambda m: m.current >= 2, "waypoint 2", texts
        )
        seen["progress"] = (progress.current, progress.total)
        rtl = FlightMode.RETURN_TO_LAUNCH
        await _until(telemetry.subscribe_flight_mode(), lambda m: m == rtl, "Return", texts)
        # Home through the fence: back inside it, by its own telemetry however late it comes.
        await _until(
            telemetry.subscribe_position(),
            lambda p: frame.ne(p.latitude_deg, p.longitude_deg)[1] < FENCE_M - 200.0,
            "back inside the fence",
            texts,
        )
        await asyncio.sleep(1.0)  # the breach's own text follows the mode
        listener.cancel()
    return seen


@pytest.mark.timeout(1200)
def test_mavsdk_mission_without_take_off_flies_and_its_geofence_acts(tmp_path):
    replay = free_udp_port()
    link = ("--link", f"udpout://127.0.0.1:{replay}", "--aircraft", "c172p")
    with sim_running(tmp_path, *link) as (port, proc, truth_path):
        fence_texts = upload_fence_as_mavsdk_server(replay)
        seen = asyncio.run(_flight(port))
    out = proc.output()
    texts = seen["texts"]
    assert "Fence item 4 ignored: inclusion circle radius 0" in fence_texts, fence_texts
    assert "Hold: on the ground until Takeoff or Mission" in texts, texts  # at arming (Loiter)
    assert seen["refused"] == [ActionResult.COMMAND_DENIED] * 2
    assert "Return: on the ground, take off first" in texts, texts
    assert "Mission item 0 not a take-off: taking off first" in texts, texts
    assert seen["climbed"] > 40.0  # it took off
    # MAVSDK counts its own items: the first two waypoints were flown.
    assert seen["progress"][0] >= 2, seen["progress"]
    assert any("Fence breached" in t for t in texts), (texts, out[-2000:])
    # Turned back at the fence, by the simulator's track (the position MAVSDK hands over
    # as the mode changes is as late as the machine is busy, seconds of lockstep flight).
    truth = read_estimate(truth_path)
    frame = LocalFrame(truth["lat"][0], truth["lon"][0])
    farthest = max(frame.ne(la, lo)[1] for la, lo in zip(truth["lat"], truth["lon"], strict=True))
    assert FENCE_M < farthest < FENCE_M + 600.0, farthest
