"""A mission flown in exact lockstep SITL leaves an on-board ULog, from boot, on one time
base, that ``companion replay`` re-runs to the very estimate the vehicle made in flight."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
from pyulog import ULog

from companion.messages import NavFlags
from companion.navigation.estimate_csv import read_estimate
from ground.replay.flight_log import SENSOR_CHANNELS, flight_estimate, load
from ground.replay.single import replay_log
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
        "--duration", f"{DURATION_S:g}", "--start-at", f"{START_AT_S:g}", "--exact",
        "--gps-outage", "20:4",  # the receiver's samples without a fix are logged too
    )  # fmt: skip
    out = finish(proc, namespace, 240)
    # --exact: one file from start-up, through the arming, to the end.
    (flight,) = (tmp_path / "state" / "logs").glob("*.ulg")
    # The run says where it is, and keeps a copy beside the truth CSV.
    assert f"flight log: {flight}" in out
    assert (tmp_path / "truth.ulg").read_bytes() == flight.read_bytes()

    ulog = ULog(str(flight))
    # Simulation time throughout: no stamp from the host's clock, none after the end.
    for data in ulog.data_list:
        assert data.data["timestamp"].max() <= DURATION_S * 1e6 + 1e5, data.name
    # From boot: the file opens before the simulation's first step, at vehicle time 0.
    assert 0 <= ulog.start_timestamp <= START_AT_S * 1e6 <= ulog.last_timestamp
    assert ulog.last_timestamp <= DURATION_S * 1.01e6
    imu = ulog.get_dataset("sensors_imu").data["timestamp"]
    assert imu[0] <= 1e5  # the simulation's first IMU samples, long before the arming
    assert len(imu) > 100 * (DURATION_S - 5)

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
    assert figures["horizontal"] < 1e-3 and figures["altitude"] < 1e-3, line
    assert figures["tilt"] < 1e-3 and figures["yaw"] < 1e-3, line
    replayed = read_estimate(estimate)
    assert replayed["t"][-1] == pytest.approx(DURATION_S, abs=0.5)
    _assert_replays_to_rounding(flight, tmp_path / "again.csv")

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
    _assert_csv_replays_as_the_ulog(sensors, estimate, result.stdout, said, tmp_path)


def _replay_figures(said: str) -> tuple[str, str]:
    """The rows refused and the innovation rejections a replay printed."""
    bad = re.search(r"\((\d+) bad\)", said)
    rejections = re.search(r"innovation rejections: GPS (\d+), heading (\d+)", said)
    assert bad and rejections, said
    return bad.group(1), rejections.group(0)


def _assert_csv_replays_as_the_ulog(sensors, from_ulog, log_said, ulog_said, tmp_path) -> None:
    """The flight converted by `companion log`, the outage's no-fix samples included,
    replays with the options it printed to the very solutions of the ULog."""
    rows = [line.split(",") for line in sensors.read_text().splitlines()]
    fix = rows[0].index("fix")
    assert any(r[1] == "gps" and r[fix] in ("0", "1") for r in rows), "no no-fix sample"
    said = " ".join(log_said.split())
    options = said.split(f"companion replay {sensors} ", 1)[1].split()
    assert options == ["--declination", "11.7", "--gps-delay", "0.1"], said  # sim.toml's
    out = tmp_path / "from_csv.csv"
    # A CSV's replay publishes on its own grid (from the first sample, at the first sample
    # past each tick), the ULog's on the plug-in's: at the IMU's 100 Hz nearly every instant
    # the ULog's replay published is among the CSV's (not those after a gap in the IMU).
    result = subprocess.run(
        [sys.executable, "-m", "companion", "replay", str(sensors), "--out", str(out),
         *options, "--rate", "100"],
        cwd=REPO, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    csv_said = " ".join(result.stdout.split())
    assert _replay_figures(csv_said) == ("0", _replay_figures(ulog_said)[1]), csv_said
    a, b = from_ulog.read_text().splitlines(), out.read_text().splitlines()
    assert a[0] == b[0]
    by_time: dict[str, str] = {}
    for row in b[1:]:
        by_time.setdefault(row.split(",", 1)[0], row)
    common = [row for row in a[1:] if row.split(",", 1)[0] in by_time]
    assert len(common) > 0.95 * (len(a) - 1), (len(common), len(a))
    assert [by_time[row.split(",", 1)[0]] for row in common] == common  # to the last digit


def _assert_replays_to_rounding(flight, out) -> None:
    """Every solution the vehicle published, at its own time, as the replay computes it."""
    _, states = replay_log(flight, "ins_ekf", out)
    replayed = {s.t_us: s for s in states}
    flown = flight_estimate(load(flight))
    assert len(flown) > 40 * (DURATION_S - 5)
    worst = dict.fromkeys(
        ("lat_deg", "lon_deg", "alt_msl_m", "roll_rad", "pitch_rad", "yaw_rad"), 0.0
    )
    for logged in flown:
        again = replayed.get(logged.t_us)
        assert again is not None, f"no replayed solution at {logged.t_us} us"
        assert again.flags == logged.flags, logged.t_us
        for name in worst:
            worst[name] = max(worst[name], abs(getattr(again, name) - getattr(logged, name)))
    # Mostly bit for bit. Aiding samples of the same instant from different drivers reach
    # the navigator in the order their processes ran when they come in separate reads,
    # and the replay can only use its reading order: fusing two such samples the other way
    # round moves the estimate by rounding (seen: 4e-12 deg, 4e-8 m, 2e-7 rad).
    assert worst["lat_deg"] <= 1e-8 and worst["lon_deg"] <= 1e-8, worst  # 1 mm
    assert worst["alt_msl_m"] <= 1e-4, worst
    assert max(worst["roll_rad"], worst["pitch_rad"], worst["yaw_rad"]) <= 1e-5, worst
