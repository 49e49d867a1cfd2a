"""A first waypoint that lies behind the climb-out is flown back to (issue 42.7).

The take-off climbs east along the runway to 100 m; the plan's first waypoint is 400 m
down the runway, long passed when the climb ends, and the second lies 3 km on, a little
north of the runway's line. The leg to the first used to start where the take-off began,
so the aircraft, already beyond that waypoint's finish line and near the next leg's line,
counted it as passed and joined the next leg far beyond it. The leg now starts where the
climb ended (as ArduPlane's does): the aircraft turns back, passes the waypoint at height,
then flies the rest. Lockstep JSBSim through MAVSDK's raw mission import, as a user would.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from companion.geodesy import LocalFrame
from companion.navigation.estimate_csv import read_estimate as read_truth
from tests.sim.sim_run import with_sim
from tests.sitl.test_missions import HOME
from tests.support.mavsdk_flight import fly_plan

FIRST = (0.0, 400.0)  # north, east of home (m): on the runway's line
SECOND = (30.0, 3_000.0)  # the climb ends within WP_RADIUS of the line to it


def _plan(path) -> str:
    frame = LocalFrame(*HOME)

    def simple(seq: int, command: int, ne: tuple[float, float] | None, p1: float = 0.0) -> dict:
        lat, lon = frame.latlon(*ne) if ne is not None else (0.0, 0.0)
        alt = 100.0 if ne is not None else 0.0
        params = [p1, 0, 0, None, lat, lon, alt]
        return {"type": "SimpleItem", "command": command, "frame": 3, "autoContinue": True,
                "doJumpId": seq + 1, "params": params}  # fmt: skip

    items = [
        simple(0, 22, (0.0, 600.0), p1=15.0),  # NAV_TAKEOFF, as QGroundControl places it
        simple(1, 16, FIRST),
        simple(2, 16, SECOND),
        simple(3, 20, None),  # NAV_RETURN_TO_LAUNCH
    ]
    plan = {
        "fileType": "Plan", "version": 1, "groundStation": "QGroundControl",
        "mission": {"version": 2, "firmwareType": 12, "vehicleType": 1, "cruiseSpeed": 36,
                    "hoverSpeed": 5, "plannedHomePosition": [*HOME, 80], "items": items},
        "geoFence": {"version": 2, "polygons": [], "circles": []},
        "rallyPoints": {"version": 2, "points": []},
    }  # fmt: skip
    path.write_text(json.dumps(plan))
    return str(path)


@pytest.mark.timeout(400)
def test_a_first_waypoint_the_climb_flew_past_is_flown_back_to_at_height(tmp_path):
    plan = _plan(tmp_path / "behind.plan")
    seen, out, truth_path = with_sim(tmp_path, lambda port: fly_plan(port, plan, 300.0))
    assert seen["finished"], out[-3000:]
    truth = read_truth(truth_path)
    frame = LocalFrame(*HOME)
    ne = np.array([frame.ne(la, lo) for la, lo in zip(truth["lat"], truth["lon"], strict=True)])
    height = np.array(truth["alt"]) - truth["alt"][0]
    climbed = int(np.argmax(height > 90.0))  # the climb-out is over from here
    assert height[climbed] > 90.0
    past = ne[climbed][1] - FIRST[1]
    after = ne[climbed:]
    to_first = np.hypot(after[:, 0] - FIRST[0], after[:, 1] - FIRST[1])
    to_second = np.hypot(after[:, 0] - SECOND[0], after[:, 1] - SECOND[1])
    closest = int(np.argmin(to_first))
    # One run (c172p, calm): the climb ended 967 m past it; passed 1 m from it, 100 m up.
    what = (past, to_first[closest], height[climbed + closest])
    assert past > 300.0, what  # the plan does what it is for: the waypoint is behind the climb
    # Flown back to: passed near it, at height, before the aircraft went on to the second.
    assert to_first[closest] < 100.0, what
    assert height[climbed + closest] > 80.0, what
    assert to_second[:closest].min() > 1_000.0
    # The second is left for home (a reversal) a turn's lead early: 265 m in that run.
    assert to_second[closest:].min() < 400.0
