"""A QGroundControl plan with a Delay, a region of interest and a gimbal angle, flown whole.

QGroundControl's PX4 plug-in offers these items and PX4 flies such a plan: the delay holds
the aircraft round the waypoint before it, the gimbal items aim what a PX4 plane may carry.
This vehicle carries no gimbal: the plan must still upload and fly, the aircraft circling
the waypoint for the delay and never turning towards the region of interest 2.5 km off.
"""

from __future__ import annotations

import asyncio
import json
import math

import numpy as np
import pytest

from companion.geodesy import LocalFrame
from companion.navigation.estimate_csv import read_estimate as read_truth
from tests.protocol.mav_client import free_udp_port
from tests.sim.sim_run import finish, start_sim
from tests.support.mavsdk_flight import fly_plan

HOME = LocalFrame(-37.9105, 145.1340)
TAKEOFF, A, B, C = (0.0, 600.0), (900.0, 900.0), (900.0, -300.0), (0.0, -300.0)
ROI = (2_500.0, 3_000.0)  # 2.4 km or more from every leg
DELAY_S = 30.0


def _item(command: int, frame: int, params: list, seq: int) -> dict:
    return {"type": "SimpleItem", "autoContinue": True, "command": command,
            "doJumpId": seq, "frame": frame, "params": params}  # fmt: skip


def _at(ne: tuple[float, float], alt: float) -> list:
    lat, lon = HOME.latlon(*ne)
    return [lat, lon, alt]


def _plan() -> dict:
    """As QGroundControl 4.4 saves them: NAV_DELAY with its time-of-day fields -1 and no
    place (frame 2, MISSION), DO_SET_ROI_LOCATION, DO_MOUNT_CONTROL (a waypoint's camera
    section's gimbal pitch), then two more waypoints."""
    items = [
        _item(22, 3, [15, 0, 0, None, *_at(TAKEOFF, 60.0)], 1),
        _item(16, 3, [0, 0, 0, None, *_at(A, 100.0)], 2),
        _item(93, 2, [DELAY_S, -1, -1, -1, 0, 0, 0], 3),
        _item(195, 3, [0, 0, 0, 0, *_at(ROI, 0.0)], 4),
        _item(205, 2, [-45, 0, 0, 0, 0, 0, 2], 5),
        _item(16, 3, [0, 0, 0, None, *_at(B, 100.0)], 6),
        _item(16, 3, [0, 0, 0, None, *_at(C, 100.0)], 7),
    ]
    mission = {"version": 2, "firmwareType": 12, "vehicleType": 1, "cruiseSpeed": 15,
               "hoverSpeed": 5, "plannedHomePosition": [-37.9105, 145.134, 126],
               "items": items}  # fmt: skip
    return {"fileType": "Plan", "version": 1, "groundStation": "QGroundControl",
            "mission": mission, "geoFence": {"version": 2, "polygons": [], "circles": []},
            "rallyPoints": {"version": 2, "points": []}}  # fmt: skip


@pytest.mark.timeout(300)
def test_a_delay_holds_the_aircraft_round_its_waypoint_and_gimbal_items_change_nothing(
    tmp_path,
):
    plan = tmp_path / "delay_gimbal.plan"
    plan.write_text(json.dumps(_plan()))
    port = free_udp_port()
    proc, namespace, truth_path = start_sim(
        tmp_path, f"udpout://127.0.0.1:{port}", "--aircraft", "c172p", "--duration", "330"
    )
    try:
        seen = asyncio.run(fly_plan(port, str(plan), 240.0))
    finally:
        out = finish(proc, namespace, 240)
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
