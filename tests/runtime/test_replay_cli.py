"""``companion replay``: a synthetic log in, the estimate CSV and a plot out; bad rows named."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from companion.navigation.estimate_csv import COLUMNS, read_estimate
from ground.simulation.synthetic_flight import FlightSpec, Leg
from ground.simulation.synthetic_log import synthesize
from tests.support.vehicle import REPO


@pytest.mark.timeout(120)
@pytest.mark.parametrize("navigator", ["ins_ekf", "gps_compass"])
def test_replay_writes_the_estimate_and_a_plot(tmp_path, navigator):
    spec = FlightSpec(legs=(Leg(30), Leg(20, turn_deg_s=8), Leg(10)), seed=3)
    log, truth, estimate, plot = (tmp_path / n for n in ("s.csv", "t.csv", "e.csv", "p.png"))
    synthesize(spec).write(log, truth)
    with log.open("a") as f:
        f.write("61.0,imu,1,2\n61.1,warp,,\n")  # a truncated row and an unknown kind
    result = subprocess.run(
        [sys.executable, "-m", "companion", "replay", str(log), "--out", str(estimate),
         "--navigator", navigator, "--declination", "11.7", "--plot", str(plot),
         "--truth", str(truth)],
        cwd=REPO, capture_output=True, text=True, timeout=100,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "2 bad" in result.stdout
    assert estimate.read_text().splitlines()[0] == ",".join(COLUMNS)
    est, true = read_estimate(estimate), read_estimate(truth)
    assert len(est["t"]) == pytest.approx(60 * 50, rel=0.02)  # 50 Hz of log time
    north_error = np.radians(est["lat"][-1] - true["lat"][-1]) * 6.37e6
    assert abs(north_error) < 10.0
    assert plot.stat().st_size > 20_000


def test_a_missing_log_is_a_clear_error(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "companion", "replay", str(tmp_path / "nope.csv"), "--out",
         str(tmp_path / "e.csv")],
        cwd=REPO, capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert result.returncode == 2 and "no such file" in result.stderr


def test_a_file_that_is_not_a_ulog_is_a_clear_error(tmp_path):
    broken = tmp_path / "flight.ulg"
    broken.write_bytes(b"ULog\x01garbage")
    result = subprocess.run(
        [sys.executable, "-m", "companion", "replay", str(broken), "--out",
         str(tmp_path / "e.csv")],
        cwd=REPO, capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert result.returncode == 2 and "not a readable ULog file" in result.stderr, result.stderr
