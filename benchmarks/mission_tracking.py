"""How well the whole vehicle flies the shipped plans, scored from the simulator's truth.

Usage: uv run python benchmarks/mission_tracking.py [--aircraft c172p] [--plan square.plan]
       [--lockstep exact|fast|both] [--calm-only]
(aircraft and plan repeatable; default: c172p and J3Cub, square.plan and jump.plan, exact)

``--lockstep fast`` flies the same flights in fast lockstep (``--fast``: the vehicle may
trail the physics by one navigation period, never more), ``both`` flies each both ways,
so the two can be compared (issue 20: within noise of each other, also on a busy machine).

For each airframe, plan and condition (calm; 5 m/s wind from the west with light
turbulence) it flies one campaign flight (``companion sim --speed max --exact
--start-at 10`` with the plan preloaded, so every run of the same code flies the same
flight; watched until the mission completes; ground/campaign/flight_run.py) and
prints from the truth CSV:
cross-track error RMS and 95th percentile on the straight part of each
waypoint-to-waypoint leg (past the turn onto it and before the turn off it), and height
error RMS and airspeed error RMS over the same samples (ground/campaign/scoring.py).
Targets (issue 8): calm cross-track RMS ≤ 3 m, height RMS ≤ 3 m; in wind the mission
completes and cross-track p95 ≤ 10 m.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from itertools import product
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from ground.campaign.flight_run import FlightJob, fly_flight  # noqa: E402
from ground.campaign.spec import PLANS, SIM_CONFIG, Flight  # noqa: E402

CONDITIONS = {"calm": ((0.0, 0.0, 0.0), "none"), "wind 5 m/s W + light": ((0.0, 5.0, 0.0), "light")}
START_AT_S = 10.0  # exact lockstep: the simulator arms and starts the mission then


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--aircraft", action="append")
    ap.add_argument("--plan", action="append")
    ap.add_argument("--lockstep", choices=("exact", "fast", "both"), default="exact")
    ap.add_argument("--calm-only", action="store_true")
    args = ap.parse_args()
    modes = {"exact": [False], "fast": [True], "both": [False, True]}[args.lockstep]
    conditions = {"calm": CONDITIONS["calm"]} if args.calm_only else CONDITIONS
    aircraft = args.aircraft or ["c172p", "J3Cub"]
    plans = [PLANS / p for p in (args.plan or ["square.plan", "jump.plan"])]
    head = f"{'airframe':8} {'plan':12} {'condition':22} {'pace':5} {'done':5} {'xt rms':>7}"
    head += f" {'xt p95':>7}"
    print(head + f" {'alt rms':>8} {'spd rms':>8} {'n':>6}")
    for name in aircraft:
        for plan in plans:
            for (cond, (wind, turbulence)), fast in product(conditions.items(), modes):
                flight = Flight(str(plan), name, wind, turbulence, (), 1, str(SIM_CONFIG),
                                False, 900.0, START_AT_S, fast)  # fmt: skip
                with tempfile.TemporaryDirectory() as tmp:
                    r = fly_flight(FlightJob(flight, tmp, timeout_s=600.0))
                done = r["completed"] if r["status"] == "ok" else r["error"]
                pace = "fast" if fast else "exact"
                print(
                    f"{name:8} {plan.stem:12} {cond:22} {pace:5} {done!s:5} "
                    f"{r['xtrack_rms_m']:7.2f} {r['xtrack_p95_m']:7.2f} {r['alt_rms_m']:8.2f} "
                    f"{r['airspeed_rms_m_s']:8.2f} {r['samples']:6d}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
