"""A mission flown in lockstep SITL leaves an on-board ULog that is on one time base and
that ``companion replay`` re-runs, landing near the estimate the vehicle made in flight."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
from pyulog import ULog

from companion.messages import NavFlags
from companion.navigation.estimate_csv import read_estimate
from ground.replay.flight_log import SENSOR_CHANNELS
from tests.protocol.mav_client import free_udp_port
from tests.sim.sim_run import finish, start_sim
from tests.support.vehicle import REPO

DURATION_S = 40.0
START_AT_S = 3.0


@pytest.mark.timeout(300)
def test_a_flown_ulog_replays_near_the_flight_estimate(tmp_path):
    port = free_udp_port()
    proc, namespace, _ = start_sim(
        tmp_path, f"udpout://127.0.0.1:{port}", "--plan", str(REPO / "qgc_plans/square.plan"),
        "--duration", f"{DURATION_S:g}", "--start-at", f"{START_AT_S:g}",
    )  # fmt: skip
    finish(proc, namespace, 240)
    (flight,) = (tmp_path / "state" / "logs").glob("*_armed.ulg")

    ulog = ULog(str(flight))
    # Simulation time throughout: no stamp from the host's clock, none after the end.
    for data in ulog.data_list:
        assert data.data["timestamp"].max() <= DURATION_S * 1e6 + 1e5, data.name
    assert START_AT_S * 1e6 <= ulog.start_timestamp <= ulog.last_timestamp <= DURATION_S * 1.01e6
    assert len(ulog.get_dataset("sensors_imu").data["timestamp"]) > 100 * (DURATION_S - 5)

    estimate = tmp_path / "replayed.csv"
    result = subprocess.run(
        [sys.executable, "-m", "companion", "replay", str(flight), "--out", str(estimate),
         "--declination", "11.7", "--gps-delay", "0.1"],  # the nav plug-in's in sim.toml
        cwd=REPO, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    said = " ".join(result.stdout.split())  # the console may wrap its lines
    assert "against the estimate made in flight" in said, said
    figures = {k: float(v) for k, v in re.findall(r"(\w+) RMS ([0-9.]+)", said)}
    line = said
    # Quiet runs see 0.3 m, 0.6 m, 0.2° and 0.7°; a navigator starved of CPU in flight lags.
    assert figures["horizontal"] < 5.0 and figures["altitude"] < 3.0, line
    assert figures["tilt"] < 1.5 and figures["yaw"] < 3.0, line
    replayed = read_estimate(estimate)
    assert replayed["t"][-1] == pytest.approx(DURATION_S, abs=0.5)

    # The same flight as CSV for the older tools: every sensor sample, and the estimate.
    sensors, flown = tmp_path / "sensors.csv", tmp_path / "flown.csv"
    result = subprocess.run(
        [sys.executable, "-m", "companion", "log", str(flight), "--out", str(sensors),
         "--estimate", str(flown)],
        cwd=REPO, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    # Every navigation sensor's sample (the pilot's sticks, also under sensors/, are not one).
    navigation = {channel.replace("/", "_") for channel in SENSOR_CHANNELS}
    logged = sum(len(d.data["timestamp"]) for d in ulog.data_list if d.name in navigation)
    assert len(sensors.read_text().splitlines()) == logged + 1
    in_flight = read_estimate(flown)
    nav = ulog.get_dataset("nav_state").data
    valid = int((nav["flags"] & int(NavFlags.POSITION_VALID) != 0).sum())
    assert len(in_flight["t"]) == valid > 20 * (DURATION_S - 10)
