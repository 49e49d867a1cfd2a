"""How well the whole vehicle flies the shipped plans, scored from the simulator's truth.

Usage: uv run python benchmarks/mission_tracking.py [--aircraft c172p] [--plan square.plan]
       [--lockstep exact|fast|both] [--calm-only] [--noise 1] [--gps-wander M]
(aircraft and plan repeatable; default: c172p and J3Cub, the plans in DEFAULT_PLANS, exact)

``--gps-wander 0`` keeps every sensor's noise but the GPS's slowly wandering error (1 m
per axis, 60 s correlation: a receiver without corrections), which the navigation solution
carries and no guidance can see; what is left of the cross-track error is guidance's.

``--lockstep fast`` flies the same flights in fast lockstep (``--fast``: the vehicle may
trail the physics by one navigation period, never more), ``both`` flies each both ways,
so the two can be compared (issue 20: within noise of each other, also on a busy machine).

For each airframe, plan and condition (calm; 5 m/s wind from the west with light
turbulence) it flies one campaign flight (``companion sim --speed max --exact
--start-at 10`` with the plan preloaded, so every run of the same code flies the same
flight; watched until the mission completes; ground/campaign/flight_run.py) and
prints from the truth CSV the campaign's score (ground/campaign/scoring.py): cross-track
error RMS and 95th percentile, height error RMS and airspeed error RMS, over the straight
parts of the legs as flown (more than 500 m from either corner) pooled; then, per leg as
flown (ground/campaign/legs.py, the same samples): the turn onto it, the distance flown
from its first waypoint until within 2 m of the line for good, the cross-track RMS / p95 /
mean and height RMS on its straight part, and the bank-angle and heading standard
deviations there (the wobble).
Targets (issue 27): calm cross-track RMS ≤ 1 m and p95 ≤ 2 m, in 5 m/s wind with light
turbulence p95 ≤ 3 m, height RMS ≤ 1 m, settled within 600 m after a 90° turn and 900 m
after 135°.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from itertools import product
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from companion.control.mission.plan import checked_plan  # noqa: E402
from companion.navigation.estimate_csv import read_estimate  # noqa: E402
from ground.campaign.flight_run import FlightJob, fly_flight  # noqa: E402
from ground.campaign.legs import LegFigures, flight_legs  # noqa: E402
from ground.campaign.spec import PLANS, SIM_CONFIG, Flight  # noqa: E402

CONDITIONS = {"calm": ((0.0, 0.0, 0.0), "none"), "wind 5 m/s W + light": ((0.0, 5.0, 0.0), "light")}
# The shipped plans and three long ones (benchmarks/plans/): a 3 km square, a zigzag of
# 90° turns, and a DO_JUMP loop with two 135° turns.
DEFAULT_PLANS = ["square.plan", "jump.plan", "square_3km.plan", "zigzag.plan", "jump_135.plan"]
HERE_PLANS = Path(__file__).resolve().parent / "plans"
START_AT_S = 10.0  # exact lockstep: the simulator arms and starts the mission then


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--aircraft", action="append")
    ap.add_argument("--plan", action="append")
    ap.add_argument("--lockstep", choices=("exact", "fast", "both"), default="exact")
    ap.add_argument("--calm-only", action="store_true")
    ap.add_argument("--noise", type=float, default=1.0, help="sensor noise scale (0: perfect)")
    ap.add_argument("--gps-wander", type=float, help="the GPS's wandering error, m per axis "
                    "(default: the receiver model's 1 m; 0: only its white noise)")  # fmt: skip
    args = ap.parse_args()
    modes = {"exact": [False], "fast": [True], "both": [False, True]}[args.lockstep]
    conditions = {"calm": CONDITIONS["calm"]} if args.calm_only else CONDITIONS
    aircraft = args.aircraft or ["c172p", "J3Cub"]
    plans = [_plan(p) for p in (args.plan or DEFAULT_PLANS)]
    head = f"{'airframe':8} {'plan':12} {'condition':22} {'pace':5} {'done':5} {'xt rms':>7}"
    head += f" {'xt p95':>7}"
    print(head + f" {'alt rms':>8} {'spd rms':>8} {'n':>6}")
    for name in aircraft:
        for plan in plans:
            for (cond, (wind, turbulence)), fast in product(conditions.items(), modes):
                flight = Flight(str(plan), name, wind, turbulence, (), 1, str(SIM_CONFIG),
                                False, 900.0, START_AT_S, fast, args.noise,
                                args.gps_wander)  # fmt: skip
                with tempfile.TemporaryDirectory() as tmp:
                    r = fly_flight(FlightJob(flight, tmp, timeout_s=600.0))
                    legs = _legs(Path(tmp) / flight.flight_id / "truth.csv", plan, name, wind)
                done = r["completed"] if r["status"] == "ok" else r["error"]
                pace = "fast" if fast else "exact"
                print(
                    f"{name:8} {plan.stem:12} {cond:22} {pace:5} {done!s:5} "
                    f"{r['xtrack_rms_m']:7.2f} {r['xtrack_p95_m']:7.2f} {r['alt_rms_m']:8.2f} "
                    f"{r['airspeed_rms_m_s']:8.2f} {r['samples']:6d}",
                    flush=True,
                )
                for k, leg in enumerate(legs):
                    print(_leg_row(k, leg), flush=True)


def _plan(name: str) -> Path:
    """A plan by path, or by name from qgc_plans/ or benchmarks/plans/."""
    for candidate in (Path(name), PLANS / name, HERE_PLANS / name):
        if candidate.exists():
            return candidate.resolve()
    raise SystemExit(f"no plan {name}")


def _legs(truth: Path, plan: Path, airframe: str, wind: tuple) -> list[LegFigures]:
    if not truth.exists():
        return []
    return flight_legs(read_estimate(truth), checked_plan(plan)[0], airframe, wind)


def _leg_row(k: int, f: LegFigures) -> str:
    return (
        f"    leg {k + 1}: turn {f.turn_deg:5.0f}° length {f.length_m:5.0f} m "
        f"settled {f.settled_m:5.0f} m | xt rms {f.xt_rms_m:5.2f} p95 {f.xt_p95_m:5.2f} "
        f"mean {f.xt_mean_m:+5.2f} height rms {f.height_rms_m:4.2f} | "
        f"bank sd {f.bank_sd_deg:4.2f}° heading sd {f.heading_sd_deg:4.2f}° n {f.samples}"
    )


if __name__ == "__main__":
    main()
