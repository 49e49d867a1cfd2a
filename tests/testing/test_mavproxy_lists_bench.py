"""MAVProxy's own wp, fence and rally commands (``wp list``, ``fence list``, ``rally
list``) on the plug-in's bench vehicle, through its ``mavproxy_master`` connection string:
a QGroundControl plan with a mission, an inclusion polygon and a rally point goes up with
the plug-in's helper, and MAVProxy reads each part back and saves it, item for item."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from tests.protocol.test_mavproxy import MavProxy
from tests.support.vehicle import REPO, wait_for

HOME = (-37.9105, 145.1340)


def fenced_plan(path: Path) -> Path:
    """short_leg.plan with a 0.06° inclusion square round home and one rally point."""
    plan = json.loads((REPO / "qgc_plans" / "short_leg.plan").read_text())
    lat, lon, d = *HOME, 0.03
    square = [[lat - d, lon - d], [lat + d, lon - d], [lat + d, lon + d], [lat - d, lon + d]]
    plan["geoFence"]["polygons"] = [{"inclusion": True, "version": 1, "polygon": square}]
    plan["rallyPoints"]["points"] = [[lat + 0.005, lon + 0.005, 100.0]]
    path.write_text(json.dumps(plan))
    return path


@pytest.mark.timeout(300)
def test_mavproxy_lists_the_mission_fence_and_rally_points(bench, tmp_path):
    bench.wait_ready()
    assert bench.upload_plan(fenced_plan(tmp_path / "fenced.plan")) == {0: 3, 1: 4, 2: 1}
    mavproxy = MavProxy(bench.mavproxy_master, tmp_path)
    lines = mavproxy.lines
    try:
        # Typed once MAVProxy has its parameters: a list asked before is not answered.
        wait_for(lambda: any("parameters to" in line for line in lines), 120, "MAVProxy's params")
        for command, saved in (("wp list", "way.txt"), ("fence list", "fence-items.txt"),
                               ("rally list", "rally-items.txt")):  # fmt: skip
            mavproxy.type(command)
            wait_for(lambda s=saved: any(f"to {s}" in line for line in lines), 60, command)
            time.sleep(0.5)
    finally:
        out = mavproxy.close()
    assert "Saved 3 waypoints" in out and "Saved 4 fence items" in out, out[-3000:]
    assert "Saved 1 rally items" in out, out[-3000:]
    fence = (tmp_path / "fence-items.txt").read_text()
    assert fence.count("5001") == 4, fence  # MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION
