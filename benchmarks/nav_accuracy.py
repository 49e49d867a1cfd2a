"""Navigator accuracy on synthetic flights and on real flight logs (and on simulator truth
when given).

Usage: uv run python benchmarks/nav_accuracy.py [--seeds 4] [--sim-log S.csv --sim-truth T.csv]
       [--navlogs ../shared/navlogs]

Each seed flies the six-minute circuit of ``ground.simulation.synthetic_flight`` with a
VN-100-class IMU (noise, turn-on biases, drift), a magnetometer, an OS-3000 that levels
itself with its accelerometer, and a GPS whose error wanders (1 m per axis, 60 s), with a
30 s GPS outage in a turn. Printed per navigator: RMS and 95th percentile of tilt (roll
and pitch), yaw, horizontal position and velocity error (position and velocity while GPS
is available), and the horizontal error at the end of the outage. Targets for ins_ekf:
tilt ≤ 0.5°, yaw ≤ 2°, position ≤ 2 m RMS, ≤ 30 m after the outage. For scale, the GPS
alone is printed too.

Then the real flight logs of ``--navlogs`` (five fixed-wing, four multicopter), scored
against the autopilot's own estimate beside a complementary filter: ``nav_real_logs.py``.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from nav_real_logs import NAVLOGS, real_log_table  # beside this script

from companion.messages import GpsFix
from companion.navigation.estimate_csv import read_estimate
from companion.navigation.scoring import EARTH_RADIUS_M, Errors
from ground.simulation.evaluation import fly, messages, truth_columns
from ground.simulation.synthetic_flight import FlightSpec
from ground.simulation.synthetic_log import synthesize

OUTAGE = (150.0, 30.0)
DECLINATION = 11.7  # the synthetic field's
FIELDS = ("tilt_rms_deg", "tilt_p95_deg", "yaw_rms_deg", "yaw_p95_deg", "pos_rms_m",
          "pos_p95_m", "vel_rms_m_s", "vel_p95_m_s", "outage_end_m")  # fmt: skip


def gps_alone(flight) -> float:
    """Horizontal RMS error of the GPS fixes themselves."""
    truth = truth_columns(flight)
    errors = []
    for fix in (m for m in messages(flight) if isinstance(m, GpsFix)):
        t = fix.t_us / 1e6
        north = math.radians(fix.lat_deg - np.interp(t, truth["t"], truth["lat"])) * EARTH_RADIUS_M
        east = math.radians(fix.lon_deg - np.interp(t, truth["t"], truth["lon"])) * EARTH_RADIUS_M
        errors.append(math.hypot(north, east * math.cos(math.radians(fix.lat_deg))))
    return float(np.sqrt(np.mean(np.square(errors))))


def table(title: str, rows: dict[str, list[Errors]]) -> None:
    print(f"\n{title}")
    print(f"{'navigator':12s} " + " ".join(f"{f:>13s}" for f in FIELDS))
    for name, errs in rows.items():
        means = [np.nanmean([getattr(e, f) for e in errs]) for f in FIELDS]
        worst = [np.nanmax([getattr(e, f) for e in errs]) for f in FIELDS]
        print(f"{name:12s} " + " ".join(f"{m:13.2f}" for m in means) + "   (mean)")
        print(f"{'':12s} " + " ".join(f"{w:13.2f}" for w in worst) + "   (worst)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--sim-estimate", type=Path, help="an estimate CSV from the simulator")
    parser.add_argument("--sim-truth", type=Path, help="the simulator's truth CSV for it")
    parser.add_argument("--navlogs", type=Path, default=NAVLOGS, help="the real-log set")
    args = parser.parse_args()
    rows: dict[str, list[Errors]] = {"ins_ekf": [], "gps_compass": []}
    gps = []
    for seed in range(1, args.seeds + 1):
        flight = synthesize(FlightSpec(outage=OUTAGE, seed=seed))
        gps.append(gps_alone(flight))
        for name in rows:
            errors, _ = fly(name, flight, DECLINATION, OUTAGE)
            rows[name].append(errors)
    table(f"synthetic circuit, {args.seeds} seeds, 30 s GPS outage at 150 s", rows)
    print(f"\nGPS alone: horizontal RMS {np.mean(gps):.2f} m (mean over seeds)")
    if args.sim_estimate and args.sim_truth:
        from companion.navigation.scoring import score

        errors = score(read_estimate(args.sim_estimate), read_estimate(args.sim_truth))
        table("simulator run", {"estimate": [errors]})
    print("\nreal flight logs (reference: the autopilot's own estimate; first 10 s skipped)")
    print("\n".join(real_log_table(args.navlogs)))


if __name__ == "__main__":
    main()
