"""How well the whole vehicle flies the shipped plans, scored from the simulator's truth.

Usage: uv run python benchmarks/mission_tracking.py [--aircraft c172p] [--plan square.plan]
(both repeatable; default: c172p and J3Cub, square.plan and jump.plan)

For each airframe, plan and condition (calm; 5 m/s wind from the west with light
turbulence) it runs ``companion sim --speed max`` with the plan preloaded, arms and starts
the mission over MAVLink as a ground station would, waits for the mission to complete,
and prints from the truth CSV: cross-track error RMS and 95th percentile on the straight
part of each waypoint-to-waypoint leg (past the turn onto it and before the turn off it),
and height error RMS and airspeed error RMS over the same samples.
Targets (issue 8): calm cross-track RMS ≤ 3 m, height RMS ≤ 3 m; in wind the mission
completes and cross-track p95 ≤ 10 m.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from companion.actuators.airframe import load_airframe  # noqa: E402
from companion.estimation.estimate_csv import read_estimate  # noqa: E402
from companion.flight.params import control_params  # noqa: E402
from companion.geodesy import LocalFrame  # noqa: E402
from companion.mission.executor import RELATIVE_FRAMES  # noqa: E402
from companion.mission.plan import checked_plan  # noqa: E402
from mavlink_dialect import companion as d  # noqa: E402

CONDITIONS = {"calm": ("0,0,0", "none"), "wind 5 m/s W + light": ("0,5,0", "light")}
G = 9.80665


@dataclass
class Score:
    completed: bool
    xtrack_rms: float
    xtrack_p95: float
    alt_rms: float
    aspd_rms: float
    samples: int


def fly(aircraft: str, plan: Path, wind: str, turbulence: str, tmp: Path) -> tuple[dict, dict]:
    """Run one flight; returns the truth columns and the mission timeline."""
    port = _free_port()
    truth = tmp / "truth.csv"
    cmd = [
        sys.executable, "-m", "companion", "sim", "--speed", "max", "--aircraft", aircraft,
        "--plan", str(plan), "--wind", wind, "--turbulence", turbulence, "--duration", "900",
        "--truth", str(truth), "--state-dir", str(tmp / "state"),
        "--namespace", f"bench{os.getpid()}_{port}", "--link", f"udpout://127.0.0.1:{port}",
    ]  # fmt: skip
    gcs = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=255)
    proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
    try:
        timeline = _run_mission(gcs)
    finally:
        proc.terminate()
        proc.wait(timeout=30)
        gcs.close()
    return read_estimate(truth), timeline


def _run_mission(gcs) -> dict:
    """Arm, MISSION_START, then follow MISSION_CURRENT until the mission is complete."""
    gcs.recv_match(type="HOME_POSITION", blocking=True, timeout=120)
    for command, p1 in ((d.MAV_CMD_COMPONENT_ARM_DISARM, 1), (d.MAV_CMD_MISSION_START, 0)):
        gcs.mav.command_long_send(1, 1, command, 0, p1, 0, 0, 0, 0, 0, 0)
        gcs.recv_match(type="COMMAND_ACK", blocking=True, timeout=10)
    seqs: list[int] = []
    started = time.monotonic()
    while time.monotonic() - started < 240:
        msg = gcs.recv_match(type="MISSION_CURRENT", blocking=True, timeout=1)
        if msg is None:
            continue
        seqs.append(msg.seq)
        if msg.mission_state == d.MISSION_STATE_COMPLETE:
            time.sleep(1.0)  # a little of the circling at home into the truth file
            return {"seqs": seqs, "completed": True}
    return {"seqs": seqs, "completed": False}


def _free_port() -> int:
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def score(aircraft: str, plan: Path, truth: dict, timeline: dict, wind: str) -> Score:
    """Cross-track, height and airspeed errors on the straight parts of the legs.

    Airspeed is the truth's ground velocity less the steady wind the run was given (the
    truth file has no airspeed column; turbulence is left in, as a pitot would see it).
    """
    values = {p.name: p.default for p in control_params(load_airframe(aircraft).control)}
    cruise = values["AIRSPEED_CRUISE"]
    radius = cruise**2 / (G * math.tan(math.radians(values["ROLL_LIMIT_DEG"]) * 0.8))
    l1 = values["NAVL1_DAMPING"] * values["NAVL1_PERIOD"] * cruise / math.pi
    margin = radius + l1
    items = checked_plan(plan)[0]
    lat, lon = np.array(truth["lat"]), np.array(truth["lon"])
    alt = np.array(truth["alt"])
    frame = LocalFrame(lat[0], lon[0])
    north, east = np.array([frame.ne(a, b) for a, b in zip(lat, lon, strict=True)]).T
    home_alt = alt[0]
    wn, we, wd = (float(v) for v in wind.split(","))
    speed = np.sqrt(
        (np.array(truth["vn"]) - wn) ** 2
        + (np.array(truth["ve"]) - we) ** 2
        + (np.array(truth["vd"]) - wd) ** 2
    )
    xt, dz, dv = [], [], []
    for i in range(1, len(items)):
        a, b = items[i - 1], items[i]
        if a.command != d.MAV_CMD_NAV_WAYPOINT or b.command != d.MAV_CMD_NAV_WAYPOINT:
            continue  # only waypoint-to-waypoint legs are straight lines
        pa, pb = frame.ne(a.x / 1e7, a.y / 1e7), frame.ne(b.x / 1e7, b.y / 1e7)
        length = math.hypot(pb[0] - pa[0], pb[1] - pa[1])
        u = ((pb[0] - pa[0]) / length, (pb[1] - pa[1]) / length)
        along = (north - pa[0]) * u[0] + (east - pa[1]) * u[1]
        cross = -(north - pa[0]) * u[1] + (east - pa[1]) * u[0]
        on_leg = (along > margin) & (along < length - margin) & (np.abs(cross) < 150)
        target = b.z + (home_alt if b.frame in RELATIVE_FRAMES else 0.0)
        xt += list(cross[on_leg])
        dz += list(alt[on_leg] - target)
        dv += list(speed[on_leg])
    xt_a, dz_a = np.abs(np.array(xt)), np.array(dz)
    return Score(
        timeline["completed"],
        float(np.sqrt(np.mean(xt_a**2))) if len(xt_a) else math.nan,
        float(np.percentile(xt_a, 95)) if len(xt_a) else math.nan,
        float(np.sqrt(np.mean(dz_a**2))) if len(dz_a) else math.nan,
        float(np.sqrt(np.mean((np.array(dv) - cruise) ** 2))) if dv else math.nan,
        len(xt_a),
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--aircraft", action="append")
    ap.add_argument("--plan", action="append")
    args = ap.parse_args()
    aircraft = args.aircraft or ["c172p", "J3Cub"]
    plans = [REPO / "qgc_plans" / p for p in (args.plan or ["square.plan", "jump.plan"])]
    head = f"{'airframe':8} {'plan':12} {'condition':22} {'done':5} {'xt rms':>7} {'xt p95':>7}"
    print(head + f" {'alt rms':>8} {'spd rms':>8} {'n':>6}")
    for name in aircraft:
        for plan in plans:
            for cond, (wind, turb) in CONDITIONS.items():
                with tempfile.TemporaryDirectory() as tmp:
                    truth, timeline = fly(name, plan, wind, turb, Path(tmp))
                s = score(name, plan, truth, timeline, wind)
                print(
                    f"{name:8} {plan.stem:12} {cond:22} {s.completed!s:5} "
                    f"{s.xtrack_rms:7.2f} {s.xtrack_p95:7.2f} {s.alt_rms:8.2f} "
                    f"{s.aspd_rms:8.2f} {s.samples:6d}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
