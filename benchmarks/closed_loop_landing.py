"""The landing law alone: many crosswind landings flying JSBSim on the true state.

Usage: uv run python benchmarks/closed_loop_landing.py [--seeds 2-41] [--airframe c172p]
                                                       [--plan circuit_east.plan]

No sensors, navigator or bus (tests/support/closed_loop.py, a 12 m downward rangefinder):
what the landing law makes of one gust sequence after another. Each plan of
benchmarks/plans/ is flown once in calm air and once per JSBSim turbulence seed
(`atmosphere/randomseed`) in a 5 m/s crosswind with light turbulence, about two seconds a
flight. Scored from the truth as benchmarks/landing.py scores the whole vehicle (15 m
along, 2 m across, sink 1.5 m/s); that one's figures are the product's, these show how
often a gust defeats the law itself. Beside the scorer's touchdown (the centre of gravity
back near its height at rest, no longer sinking) it counts the landings on target with the
touchdown where JSBSim first put weight on a wheel: a skim a few decimetres above the
runway is the first, not the second.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass, replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np

from companion.control.mission.plan import checked_plan
from ground.campaign.landing_score import (
    LandingScore,
    landing_score_for_plan,
    line_coordinates,
    plan_line,
)
from tests.support.closed_loop import ClosedLoop

PLANS = Path(__file__).resolve().parent / "plans"
CROSSWIND = (5.0, 0.0, 0.0)  # m/s north: across the east-west runways of the plans
LONGEST_S = 600.0
LOW_M = 15.0  # below this, after the flight proper, the wheels are watched every step
WHEELS_STEP_S = 0.02


@dataclass(frozen=True)
class Landed:
    """The scorer's landing, and where JSBSim first put weight on a wheel (along, m)."""

    score: LandingScore
    wheels_along_m: float


def fly(
    airframe: str, plan: Path, seed: int | None, crosswind: tuple[float, float, float] = CROSSWIND
) -> Landed:
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
    wheels: tuple[float, float] | None = None  # lat, lon of the first weight on wheels
    airborne = False
    while loop.flight.t_s < LONGEST_S:
        low = airborne and loop.samples and loop.samples[-1].alt_agl < LOW_M
        loop.run(WHEELS_STEP_S if low and wheels is None else 1.0)
        airborne = airborne or loop.samples[-1].alt_agl > LOW_M
        if airborne and wheels is None and _weight_on_wheels(loop):
            wheels = (
                loop.flight.fdm["position/lat-geod-deg"],
                loop.flight.fdm["position/long-gc-deg"],
            )
        if loop.samples[-1].out.disarm:
            break
    along = math.nan
    if wheels is not None:
        line = plan_line(items)
        along = float(line_coordinates(np.array([wheels[0]]), np.array([wheels[1]]), *line)[0][0])
    return Landed(landing_score_for_plan(loop.truth(), items), along)


def _weight_on_wheels(loop: ClosedLoop) -> bool:
    """Whether a wheel carries weight (JSBSim numbers its structural contact points
    among the gear too, and those have no WOW)."""
    fdm = loop.flight.fdm
    for i in range(int(fdm["gear/num-units"])):
        try:
            if fdm[f"gear/unit[{i}]/WOW"] > 0.5:
                return True
        except KeyError:
            return False
    return False


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
            off = [f"seed {s} {r.score.along_m:+.1f} m (wheels {r.wheels_along_m:+.1f})"
                   for s, r in runs.items() if not r.score.passed()]  # fmt: skip
            along = [r.score.along_m for r in runs.values()]
            print(
                f"{airframe:6} {name:18} calm {calm.score.along_m:+6.1f} m (wheels "
                f"{calm.wheels_along_m:+.1f}) {'on' if calm.score.passed() else 'OFF'} | "
                f"crosswind {sum(r.score.passed() for r in runs.values())}/{len(runs)} on "
                f"target (by the first weight on wheels {sum(map(_on_by_wheels, runs.values()))}"
                f"), along {min(along):+.1f}..{max(along):+.1f} m, mean "
                f"{sum(along) / len(along):+.1f}{' | off: ' + ', '.join(off) if off else ''}",
                flush=True,
            )


def _on_by_wheels(run: Landed) -> bool:
    """On target with the touchdown where the first wheel took weight."""
    return replace(run.score, along_m=run.wheels_along_m).passed()


if __name__ == "__main__":
    main()
