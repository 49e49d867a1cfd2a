"""A QGroundControl plan with a Delay, a region of interest and a gimbal angle, flown whole.

QGroundControl's PX4 plug-in offers these items and PX4 flies such a plan: the delay holds
the aircraft round the waypoint before it, the gimbal items aim what a PX4 plane may carry.
This vehicle carries no gimbal: the plan must still upload and fly, the aircraft circling
the waypoint for the delay and never turning towards the region of interest 2.5 km off.
MAVSDK's mission plug-in makes the same items of a waypoint's gimbal pitch and loiter time.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TypeVar

import numpy as np
import pytest
from mavsdk.asyncio import Configuration, Mavsdk
from mavsdk.asyncio.plugins.mission import MissionAsync
from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.component_type import ComponentType
from mavsdk.plugins.mission import MissionItem, MissionPlan

from companion.geodesy import LocalFrame
from companion.navigation.estimate_csv import read_estimate as read_truth
from mavlink_dialect import companion as d
from tests.sim.sim_run import with_sim
from tests.support.mavsdk_flight import fly_plan
from tests.support.qgc_plan import simple_item, write_plan

HOME = LocalFrame(-37.9105, 145.1340)
TAKEOFF, A, B, C = (0.0, 600.0), (900.0, 900.0), (900.0, -300.0), (0.0, -300.0)
ROI = (2_500.0, 3_000.0)  # 2.4 km or more from every leg
DELAY_S = 30.0
T = TypeVar("T")


def _at(ne: tuple[float, float], alt: float) -> list:
    lat, lon = HOME.latlon(*ne)
    return [lat, lon, alt]


def _plan(path: Path) -> Path:
    """As QGroundControl 4.4 saves them: NAV_DELAY with its time-of-day fields -1 and no
    place (frame 2, MISSION), DO_SET_ROI_LOCATION, DO_MOUNT_CONTROL (a waypoint's camera
    section's gimbal pitch), then two more waypoints."""
    items = [
        simple_item(22, 3, [15, 0, 0, None, *_at(TAKEOFF, 60.0)], 1),
        simple_item(16, 3, [0, 0, 0, None, *_at(A, 100.0)], 2),
        simple_item(93, 2, [DELAY_S, -1, -1, -1, 0, 0, 0], 3),
        simple_item(195, 3, [0, 0, 0, 0, *_at(ROI, 0.0)], 4),
        simple_item(205, 2, [-45, 0, 0, 0, 0, 0, 2], 5),
        simple_item(16, 3, [0, 0, 0, None, *_at(B, 100.0)], 6),
        simple_item(16, 3, [0, 0, 0, None, *_at(C, 100.0)], 7),
    ]
    return write_plan(path, items, (-37.9105, 145.134, 126))


@pytest.mark.timeout(300)
def test_a_delay_holds_the_aircraft_round_its_waypoint_and_gimbal_items_change_nothing(
    tmp_path,
):
    plan = _plan(tmp_path / "delay_gimbal.plan")
    seen, out, truth_path = with_sim(tmp_path, lambda port: fly_plan(port, str(plan), 240.0))
    assert seen["finished"], out[-3000:]
    assert "Mission: 2 gimbal/video/yaw items ignored" in out
    truth = read_truth(truth_path)
    t = np.array(truth["t"])
    ne = np.array([HOME.ne(la, lo) for la, lo in zip(truth["lat"], truth["lon"], strict=True)])

    def seconds_within(point: tuple[float, float], radius: float) -> float:
        near = np.hypot(ne[:, 0] - point[0], ne[:, 1] - point[1]) < radius
        return float(np.sum(np.diff(t)[near[:-1]]))

    # Turning at a waypoint keeps the aircraft some 25-30 s within 350 m of it; the delay's
    # circle round A (the c172p's is some 220 m wide) adds its seconds there, not at B.
    held, passed = seconds_within(A, 350.0), seconds_within(B, 350.0)
    assert held >= DELAY_S + 10.0 and held >= passed + 20.0, (held, passed)
    assert min(math.dist(p, ROI) for p in ne) > 1_800.0  # never turned towards it


async def _upload_as_mavsdk_mission(port: int) -> list[int]:
    """MAVSDK's own mission plug-in, a script's way: a waypoint with a gimbal pitch and a
    loiter time, then one without. The commands the vehicle stored, downloaded."""
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        system = await mavsdk.first_autopilot(timeout_s=60.0)
        home = await anext(aiter(TelemetryAsync(system).subscribe_home()))
        frame, nan = LocalFrame(home.latitude_deg, home.longitude_deg), math.nan
        a, b = frame.latlon(*A), frame.latlon(*B)
        none, fly = MissionItem.CameraAction.NONE, MissionItem.VehicleAction.NONE
        items = [
            MissionItem(*a, 60.0, 25.0, False, -45.0, 0.0, none, 20.0, nan, nan, nan, nan, fly),
            MissionItem(*b, 60.0, 25.0, True, nan, nan, none, nan, nan, nan, nan, nan, fly),
        ]
        await MissionAsync(system).upload_mission(MissionPlan(items))  # raises if refused
        stored = await MissionRawAsync(system).download_mission()
    return [item.command for item in stored]


@pytest.mark.timeout(300)
def test_a_mavsdk_mission_with_a_gimbal_pitch_and_a_loiter_time_is_taken(tmp_path):
    """MAVSDK turns a gimbal pitch into gimbal-manager items and a loiter time into
    NAV_DELAY: the upload used to be refused whole."""
    commands, out, _ = with_sim(tmp_path, _upload_as_mavsdk_mission)
    gimbal = {d.MAV_CMD_DO_GIMBAL_MANAGER_CONFIGURE, d.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW}
    assert gimbal <= set(commands) and d.MAV_CMD_NAV_DELAY in commands, commands
    assert commands.count(d.MAV_CMD_NAV_WAYPOINT) == 2
    ignored = sum(c in gimbal for c in commands)
    assert f"Mission: {ignored} gimbal/video/yaw items ignored" in out
