"""Hardware in the loop: ``companion hil`` and ``companion run`` started apart, as on a bench.

The simulator makes its device lines as ptys under a folder (``--ptys``), the vehicle is
started separately with the shipped HIL config pointed at them, on its own clock, and a
MAVSDK script flies a shipped plan over UDP. Nothing else joins the two processes: no bus,
no shared start-up. The flight is real time, so it is scored with a margin for a busy
machine (benchmarks/hil_tracking.py: 0.75 m of cross-track RMS this way, 0.63 m in exact
lockstep, on a 2-core machine under a load average of 7).
"""

from __future__ import annotations

import asyncio
import subprocess
import sys

import pytest

from companion.bus.namespace import leftover_files
from companion.navigation.estimate_csv import read_estimate
from ground.campaign.scoring import score_track
from tests.support.hil import HilRun
from tests.support.mavsdk_flight import fly_plan
from tests.support.vehicle import REPO, companion_env, unique_namespace

PLAN = REPO / "qgc_plans" / "short_leg.plan"


@pytest.mark.timeout(400)
def test_a_plan_flown_by_a_vehicle_started_apart_on_the_simulators_lines(tmp_path):
    run = HilRun(tmp_path, "--duration", "300")
    try:
        seen = asyncio.run(fly_plan(run.port, str(PLAN), 240.0))
    finally:
        statuses = run.stop()
    assert seen["finished"], run.log("vehicle")[-3000:]
    assert statuses == (0, 0), (run.log("hil")[-2000:], run.log("vehicle")[-2000:])
    # The simulator said where its lines were, and took its links away when it ended.
    paths = run.device_paths()
    assert paths["gps"] == str(run.lines / "gps") and paths["servos"] == str(run.lines / "servos")
    assert list(run.lines.iterdir()) == []
    assert leftover_files(run.namespace) == []
    score = score_track(read_estimate(run.truth), PLAN, "c172p")
    assert score.samples > 300
    assert score.xtrack_rms_m < 4.0, score
    assert score.alt_rms_m < 8.0, score


def test_hil_refuses_a_line_it_cannot_open_and_a_missing_servo_line(tmp_path):
    env = companion_env(unique_namespace("hil"))
    cmd = [sys.executable, "-m", "companion", "hil"]
    missing = str(tmp_path / "no_such_port")
    done = subprocess.run([*cmd, "--gps", "pty:" + str(tmp_path / "gps")], env=env, cwd=REPO,
                          capture_output=True, text=True, timeout=60)  # fmt: skip
    assert done.returncode == 2
    assert "needs the servo line" in done.stderr
    done = subprocess.run([*cmd, "--servos", missing + ":9600"], env=env, cwd=REPO,
                          capture_output=True, text=True, timeout=60)  # fmt: skip
    assert done.returncode != 0
    assert f"servos: cannot open {missing} at 9600 baud" in done.stderr
