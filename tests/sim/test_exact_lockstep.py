"""``companion sim --exact --start-at``: the same seed flies the same flight, frame for frame.

Two runs of a take-off in wind and moderate turbulence, the mission started by the
simulator at the same simulated second, must write identical truth files however the
machine scheduled the processes (the test suite runs them on a loaded machine).
"""

from __future__ import annotations

import numpy as np
import pytest

from companion.navigation.estimate_csv import read_estimate as read_truth
from tests.protocol.mav_client import free_udp_port
from tests.sim.sim_run import finish, start_sim
from tests.support.vehicle import REPO

PLAN = str(REPO / "qgc_plans" / "short_leg.plan")
ARGS = ("--exact", "--start-at", "5", "--plan", PLAN, "--wind", "3,2,0",
        "--turbulence", "moderate", "--seed", "11", "--duration", "70")  # fmt: skip


def _fly(tmp_path, name: str) -> tuple[bytes, str]:
    folder = tmp_path / name
    folder.mkdir()
    proc, namespace, truth = start_sim(folder, f"udpout://127.0.0.1:{free_udp_port()}", *ARGS)
    out = finish(proc, namespace, 600)  # exact lockstep runs at the pace of a busy machine
    return truth.read_bytes(), out


@pytest.mark.timeout(1300)
def test_two_exact_runs_write_the_same_truth(tmp_path):
    first, out = _fly(tmp_path, "first")
    second, _ = _fly(tmp_path, "second")
    assert "START accepted" in out and "MISSION_START accepted" in out
    assert "control stalls 0" in out
    truth = read_truth(tmp_path / "first" / "truth.csv")
    climb = np.array(truth["alt"])
    assert climb[-1] - climb[0] > 20, "the aircraft took off"
    assert first == second, "two exact runs with the same seed flew different flights"
