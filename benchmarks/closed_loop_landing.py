"""The landing law alone: many crosswind landings flying JSBSim on the true state.

Usage: uv run python benchmarks/closed_loop_landing.py [--seeds 2-41] [--airframe c172p]
                                                       [--plan circuit_east.plan]

No sensors, navigator or bus (tests/support/closed_loop.py, a 12 m downward rangefinder):
what the landing law makes of one gust sequence after another. Each plan of
benchmarks/plans/ is flown once in calm air and once per JSBSim turbulence seed
(`atmosphere/randomseed`) in a 5 m/s crosswind with light turbulence, about two seconds a
flight. Scored from the truth as benchmarks/landing.py scores the whole vehicle (15 m
along, 2 m across, sink 1.5 m/s; the touchdown where JSBSim first put weight on a wheel);
that one's figures are the product's, these show how often a gust defeats the law itself.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from companion.control.mission.plan import checked_plan
from ground.campaign.landing_score import (
    LandingScore,
    landing_score_for_plan,
)
from tests.support.closed_loop import ClosedLoop

PLANS = Path(__file__).resolve().parent / "plans"
CROSSWIND = (5.0, 0.0, 0.0)  # m/s north: across the east-west runways of the plans
LONGEST_S = 600.0


def fly(
    airframe: str, plan: Path, seed: int | None, crosswind: tuple[float, float, float] = CROSSWIND
) -> LandingScore:
    """One landing: calm air when ``seed`` is None, else ``crosswind`` (m/s north, east,
    down) with light turbulence of that seed."""
    items = checked_plan(plan)[0]
    calm = seed is None
    loop = ClosedLoop(
        airframe,
        items,
        wind_ned=(0.0, 0.0, 0.0) if calm else crosswind,
        turbulence="none" if calm else "light",
        range_max_m=12.0,
    )
    if seed is not None:
        loop.flight.fdm["atmosphere/randomseed"] = seed
    loop.fly_until_disarmed(LONGEST_S)
    return landing_score_for_plan(loop.truth(), items)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="2-41", help="turbulence seeds, FIRST-LAST")
    ap.add_argument("--airframe", action="append", help="c172p, J3Cub (default: both)")
    ap.add_argument("--plan", action="append", help="a plan in benchmarks/plans/")
    args = ap.parse_args()
    first, last = (int(x) for x in args.seeds.split("-"))
    plans = args.plan or ["circuit_east.plan", "circuit_west.plan", "land_east.plan"]
    seeds = range(first, last + 1)
    for airframe in args.airframe or ["c172p", "J3Cub"]:
        for name in plans:
            calm = fly(airframe, PLANS / name, None)
            runs = {s: fly(airframe, PLANS / name, s) for s in seeds}
            off = [f"seed {s} {r.along_m:+.1f} m" for s, r in runs.items() if not r.passed()]
            along = [r.along_m for r in runs.values()]
            print(
                f"{airframe:6} {name:18} calm {calm.along_m:+6.1f} m "
                f"{'on' if calm.passed() else 'OFF'} | crosswind "
                f"{sum(r.passed() for r in runs.values())}/{len(runs)} on target, along "
                f"{min(along):+.1f}..{max(along):+.1f} m, mean {sum(along) / len(along):+.1f}"
                f"{' | off: ' + ', '.join(off) if off else ''}",
                flush=True,
            )


if __name__ == "__main__":
    main()
