"""Automatic landings of both airframes, scored from the simulator's truth.

Usage: uv run python benchmarks/landing.py [--aircraft c172p] [--plan land_east.plan]
       [--calm-only] [--seeds N] [--start-at S ...] [--gps-receiver rtk] [--keep DIR]
(aircraft and plan repeatable; default: c172p and J3Cub, benchmarks/plans/land_east.plan)

Each airframe, plan and condition (calm; 5 m/s crosswind from the south with light
turbulence, the runway running east) is one campaign flight in exact lockstep
(``companion sim --speed max --exact --start-at 10`` with the plan, which ends in a
QGroundControl landing pattern; ground/campaign/flight_run.py), watched until the mission
completes. Printed from the truth CSV (ground/campaign/landing_score.py): touchdown
along (+ past) and across (+ right of) the landing point, vertical speed and bank at
touchdown, the highest bounce, where the aircraft stopped, and whether the vehicle's last
heartbeat said it was disarmed. ``est x`` is where the vehicle's own navigation solution
(its flight log) put it across the line at that moment: the controller's error, the rest
of ``across`` being the navigation's (the emulated GPS wanders 1 m per axis, 60 s
correlated, the same sequence for a seed whatever is flown). ``--seeds N`` flies each
row with the simulator's seeds 1 to N (the GPS's wander, the sensors' noise and the
turbulence's gusts) and ends with how many passed. Seed 1 flies JSBSim's own gust
sequence, the one every run flew before the seed picked the gusts. ``--start-at S``
(repeatable; default 10) starts the mission at another second, so the approach meets
another part of the sequence (a ground station arms on its own clock: tests/sitl/
test_landing.py holds the simulation for its arming). ``--gps-receiver rtk`` flies an RTK
receiver with a fixed solution instead (about 1 cm; ``companion sim --gps-receiver``).
Criteria (issue 24, along and across from issue 42 item 8): |along| ≤ 15 m,
|across| ≤ 2 m, sink ≤ 1.5 m/s, bounce ≤ 1 m, |bank| ≤ 10°, stopped on the runway,
disarmed. benchmarks/plans/circuit_*.plan are circuits without QGroundControl's pattern
(take-off, waypoints, NAV_LAND from the last one): ``--plan circuit_west.plan``.
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
from ground.campaign.flight_run import FlightJob, fly_flight  # noqa: E402
from ground.campaign.landing_score import (  # noqa: E402
    LandingScore,
    landing_score_for_plan,
    navigation_across,
    read_truth,
)
from ground.campaign.spec import SIM_CONFIG, Flight  # noqa: E402

CONDITIONS = {"calm": ((0.0, 0.0, 0.0), "none"), "xwind 5 S + light": ((5.0, 0.0, 0.0), "light")}
HERE_PLANS = Path(__file__).resolve().parent / "plans"
START_AT_S = 10.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--aircraft", action="append")
    ap.add_argument("--plan", action="append")
    ap.add_argument("--calm-only", action="store_true")
    ap.add_argument("--seeds", type=int, default=1, help="fly seeds 1..N of each row")
    ap.add_argument("--start-at", type=float, action="append", help="simulated second(s)")
    ap.add_argument("--gps-receiver", default="standard", choices=("standard", "rtk"))
    ap.add_argument(
        "--keep", type=Path, help="keep each flight's folder (truth, flight log, sim log) here"
    )
    args = ap.parse_args()
    conditions = {"calm": CONDITIONS["calm"]} if args.calm_only else CONDITIONS
    plans = [_plan(p) for p in (args.plan or ["land_east.plan"])]
    print(
        f"{'airframe':8} {'plan':10} {'condition':18} {'start':>5} {'seed':>4} {'along':>6} "
        f"{'across':>6} "
        f"{'est x':>6} {'sink':>5} "
        f"{'bounce':>6} {'bank':>5} {'stop@':>6} {'stop x':>6} {'stopped':7} {'runway':6} "
        f"{'disarm':6} {'pass':5}"
    )
    passed = flown = 0
    seeds = range(1, args.seeds + 1)
    for name in args.aircraft or ["c172p", "J3Cub"]:
        for plan in plans:
            for cond, (wind, turbulence) in conditions.items():
                for start, seed in product(args.start_at or [START_AT_S], seeds):
                    flight = Flight(str(plan), name, wind, turbulence, (), seed,
                                    str(SIM_CONFIG), False, 900.0, start,
                                    gps_receiver=args.gps_receiver)  # fmt: skip
                    text, ok = fly_whole_vehicle(flight, plan, args.keep)
                    row = f"{name:8} {plan.stem:10} {cond:18} {start:5g} {seed:4d} {text}"
                    print(row, flush=True)
                    passed, flown = passed + ok, flown + 1
    print(f"passed {passed} of {flown}")


def fly_whole_vehicle(flight: Flight, plan: Path, keep: Path | None = None) -> tuple[str, bool]:
    """Fly ``flight`` with ``companion sim``; its scored row and whether it passed. With
    ``keep``, the flight's folder stays there (named by its flight id)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = keep or Path(tmp)
        row = fly_flight(FlightJob(flight, str(out), timeout_s=900.0))
        truth = out / flight.flight_id / "truth.csv"
        score = _score(truth, plan)
        est = navigation_across(truth, plan, score)
    return _row(score, est, row)


def _plan(name: str) -> Path:
    for candidate in (Path(name), HERE_PLANS / name):
        if candidate.exists():
            return candidate.resolve()
    raise SystemExit(f"no plan {name}")


def _score(truth: Path, plan: Path) -> LandingScore:
    if not truth.exists():
        return LandingScore(False)
    return landing_score_for_plan(read_truth(truth), checked_plan(plan)[0])


def _row(s: LandingScore, est: float, row: dict) -> tuple[str, bool]:
    disarmed = row.get("armed_at_end") is False
    ok = s.passed() and disarmed
    text = (
        f"{s.along_m:6.1f} {s.across_m:6.2f} {est:6.2f} "
        f"{s.sink_m_s:5.2f} "
        f"{s.bounce_m:6.2f} {s.bank_deg:5.1f} {s.stop_along_m:6.0f} {s.stop_across_m:6.2f} "
        f"{s.stopped!s:7} {s.on_runway!s:6} {disarmed!s:6} {ok!s:5}"
    )
    if row["status"] != "ok":
        text += f"  ({row['error']})"
    return text, ok


if __name__ == "__main__":
    main()
