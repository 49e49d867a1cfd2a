"""pymavlink's own mavlogdump.py (the installed script, unmodified) reads the .tlog the
plug-in's vehicle records on its helpers' endpoint: the heartbeats, the upload of a
QGroundControl plan and the vehicle's acceptance of it are all in it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests.support.vehicle import REPO

PLAN = REPO / "qgc_plans" / "short_leg.plan"


@pytest.mark.timeout(300)
def test_mavlogdump_reads_the_vehicles_tlog(bench):
    bench.wait_ready()
    assert bench.upload_plan(PLAN)[0] == 3
    bench.close()  # the recording is complete once the vehicle has stopped
    script = Path(sys.executable).parent / "mavlogdump.py"
    types = "HEARTBEAT,MISSION_COUNT,MISSION_ACK"
    out = subprocess.run(
        [sys.executable, str(script), "--types", types, str(bench.tlog_path)],
        capture_output=True, text=True, timeout=120, check=True,
    ).stdout  # fmt: skip
    lines = out.splitlines()
    # Both ways are recorded: the vehicle's heartbeats (PX4's autopilot number) and the
    # helpers' upload (they send no heartbeat: they are invisible to the test's scripts).
    vehicle = [line for line in lines if "HEARTBEAT" in line and "autopilot : 12" in line]
    helpers = [line for line in lines if "MISSION_COUNT" in line and "count : 3" in line]
    acks = [line for line in lines if "MISSION_ACK" in line]
    assert vehicle and helpers, out[:2000]
    assert len(acks) == 1 and "type : 0" in acks[0], acks  # MAV_MISSION_ACCEPTED
