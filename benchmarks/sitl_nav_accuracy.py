"""The navigator inside the whole simulated vehicle, against the simulator's truth.

Usage: uv run python benchmarks/sitl_nav_accuracy.py [--aircraft c172p] [--seed 1]
       [--case NAME] (repeatable; default: every case)

Each case is one ``companion sim --speed max --exact`` run (its own namespace, state
directory and port; the vehicle's own on-board log from boot): the mission cases fly
benchmarks/plans/land_east.plan from the runway (armed and started at 10 s), the airborne
cases start at 300 m and cruise speed and fly on untended. Cases:

  quiet mount        ``--mount quiet``: the sensors without an airframe's defects
  calibrated         the residue of a good compass calibration and motor compensation
                     (about 2° of heading error), propeller vibration (the default)
  uncalibrated       ``--mount uncalibrated``: the iron and the motor's field as they are
                     (up to 8° more at full throttle), the same vibration
  calibrated 25 Hz   calibrated, the IMU at 25 Hz
  calibrated wind    calibrated, 5 m/s crosswind and light turbulence
  airborne ...       level, or banked 45° (``--airborne-bank 45``), each mount

The GPS fix is 0.12 ± 0.03 s late in every case.
Printed from the logged ``nav/state`` against the truth CSV at the same simulated
instants, from 10 s after the first valid solution: tilt (roll and pitch) RMS, yaw RMS and
largest error, horizontal position RMS and altitude RMS.
"""

from __future__ import annotations

import argparse
import itertools
import os
import socket
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from companion.messages import NavFlags  # noqa: E402
from companion.navigation.estimate_csv import read_estimate  # noqa: E402
from ground.replay.flight_log import flight_estimate, load  # noqa: E402

PLAN = REPO / "benchmarks" / "plans" / "land_east.plan"
MISSION = ["--plan", str(PLAN), "--start-at", "10", "--duration", "240"]
AIRBORNE = ["--airborne", "--duration", "90"]
CALIBRATED = ["--mount", "calibrated"]
QUIET = ["--mount", "quiet"]
CASES = {
    "quiet mount": [*MISSION, *QUIET],
    "calibrated": [*MISSION, *CALIBRATED],
    "uncalibrated": [*MISSION, "--mount", "uncalibrated"],
    "calibrated 25 Hz": [*MISSION, *CALIBRATED, "--imu-hz", "25"],
    "calibrated wind": [*MISSION, *CALIBRATED, "--wind", "5,0,0", "--turbulence", "light"],
    "airborne level cal.": [*AIRBORNE, *CALIBRATED],
    "airborne bank 45": [*AIRBORNE, "--airborne-bank", "45", *QUIET],
    "bank 45 calibrated": [*AIRBORNE, "--airborne-bank", "45", *CALIBRATED],
    "bank 45 uncal.": [*AIRBORNE, "--airborne-bank", "45", "--mount", "uncalibrated"],
}
SETTLE_S = 10.0
EARTH_RADIUS_M = 6378137.0


def fly(case: list[str], aircraft: str, seed: int, folder: Path, index: int) -> str:
    namespace = f"navacc{os.getpid()}_{index}"
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    cmd = [
        sys.executable, "-m", "companion", "sim", "--speed", "max", "--exact",
        "--aircraft", aircraft, "--seed", str(seed), "--namespace", namespace,
        "--state-dir", str(folder / "state"), "--truth", str(folder / "truth.csv"),
        "--link", f"udpout://127.0.0.1:{port}", "--log-level", "WARNING", *case,
    ]  # fmt: skip
    env = dict(os.environ, COMPANION_BUS=namespace)
    done = subprocess.run(cmd, cwd=REPO, env=env, capture_output=True, text=True, timeout=1800)
    return done.stdout + done.stderr


def errors(folder: Path) -> dict[str, float]:
    logs = sorted((folder / "state" / "logs").glob("*.ulg"))
    states = [s for p in logs for s in flight_estimate(load(p))]
    states = [s for s in states if s.flags & NavFlags.POSITION_VALID]
    truth = read_estimate(folder / "truth.csv")
    if not states:
        return {}
    t = np.array([s.t_us / 1e6 for s in states])
    keep = t >= t[0] + SETTLE_S
    t = t[keep]
    est = {
        k: np.array([getattr(s, n) for s, use in zip(states, keep, strict=True) if use])
        for k, n in (("roll", "roll_rad"), ("pitch", "pitch_rad"), ("yaw", "yaw_rad"),
                     ("lat", "lat_deg"), ("lon", "lon_deg"), ("alt", "alt_msl_m"))
    }  # fmt: skip
    k = np.clip(np.searchsorted(truth["t"], t - 1e-6), 0, len(truth["t"]) - 1)
    wrap = lambda a: (a + np.pi) % (2 * np.pi) - np.pi  # noqa: E731
    tilt = np.concatenate(
        [wrap(est["roll"] - truth["roll"][k]), wrap(est["pitch"] - truth["pitch"][k])]
    )
    yaw = np.degrees(np.abs(wrap(est["yaw"] - truth["yaw"][k])))
    north = np.radians(est["lat"] - truth["lat"][k]) * EARTH_RADIUS_M
    east = (
        np.radians(est["lon"] - truth["lon"][k]) * EARTH_RADIUS_M * np.cos(np.radians(est["lat"]))
    )
    rms = lambda x: float(np.sqrt(np.mean(np.square(x))))  # noqa: E731
    return {
        "n": float(len(t)),
        "tilt": float(np.degrees(rms(tilt))),
        "yaw": rms(yaw),
        "yaw max": float(yaw.max()),
        "pos": rms(np.hypot(north, east)),
        "alt": rms(est["alt"] - truth["alt"][k]),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--aircraft", default="c172p")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--case", action="append", choices=sorted(CASES))
    args = ap.parse_args()
    print(f"{args.aircraft}, seed {args.seed}: RMS from {SETTLE_S:g} s after alignment")
    print(
        f"{'case':18} {'n':>6} {'tilt°':>6} {'yaw°':>6} {'yaw max°':>8} {'pos m':>6} {'alt m':>6}"
    )
    for index, name in zip(itertools.count(), args.case or list(CASES), strict=False):
        with tempfile.TemporaryDirectory() as tmp:
            out = fly(CASES[name], args.aircraft, args.seed, Path(tmp), index)
            e = errors(Path(tmp))
        if not e:
            print(f"{name:18} no navigation solution logged\n{out[-2000:]}")
            continue
        print(
            f"{name:18} {e['n']:6.0f} {e['tilt']:6.2f} {e['yaw']:6.2f} {e['yaw max']:8.1f} "
            f"{e['pos']:6.2f} {e['alt']:6.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
