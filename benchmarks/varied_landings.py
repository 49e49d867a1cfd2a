"""The landing law on landing plans it was not tuned on: random runways, finals and patterns.

Usage: uv run python benchmarks/varied_landings.py [--plans 30] [--first 0] [--airframe c172p]

Plan ``k`` is drawn from a generator seeded with ``k``: a runway on a random heading near
home, a take-off, one or two waypoints up to 1.5 km out at 80-150 m, then the landing,
either a waypoint and NAV_LAND or QGroundControl's landing pattern (LOITER_TO_ALT on a 75,
150 or 250 m circle, either way round), with a final of 300-1500 m from 20-110 m (3-9° at
most, 1.3° at least). Each is flown as benchmarks/closed_loop_landing.py flies its plans
(the control laws against JSBSim on the true state, a 12 m rangefinder): once in calm air
and once in a 5 m/s crosswind across that runway with light turbulence (seed k + 2), and
scored by the same targets. The aircraft starts facing east whatever the runway, so the
take-off meets the wind from any quarter.

``--whole-vehicle`` flies each plan with the whole vehicle instead (``companion sim``
in exact lockstep, its own navigation on the emulated sensors, seed 1, started at
simulated second 10), as benchmarks/landing.py flies its plans and with its columns; the
crosswind is the same one, across each plan's runway.
"""

from __future__ import annotations

import argparse
import json
import math
import random
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.closed_loop_landing import fly
from benchmarks.landing import fly_whole_vehicle
from companion.geodesy import LocalFrame
from ground.campaign.landing_score import LandingScore
from ground.campaign.spec import SIM_CONFIG, Flight

HOME = (-37.9105, 145.134, 80.0)  # the simulator's home (bridges/jsbsim/fdm.py)
CROSSWIND_M_S = 5.0


def random_runway(k: int) -> tuple[random.Random, LocalFrame, float, tuple[float, float]]:
    """Plan ``k``'s random draws, the frame at home, its runway's heading (deg, the first
    draw) and the runway's unit vector (north, east)."""
    r = random.Random(k)
    heading = r.uniform(0.0, 360.0)
    unit = (math.cos(math.radians(heading)), math.sin(math.radians(heading)))
    return r, LocalFrame(HOME[0], HOME[1]), heading, unit


def landing_pattern(r: random.Random, land: list[float], approach: list[float], alt: float) -> dict:
    """QGroundControl's fixed-wing landing pattern onto ``land`` from ``approach`` at
    ``alt`` (m above home), its loiter's direction and radius drawn from ``r``."""
    return {
        "type": "ComplexItem", "complexItemType": "fwLandingPattern", "version": 2,
        "altitudesAreRelative": True, "landCoordinate": [*land, 0],
        "landingApproachCoordinate": [*approach, alt], "useLoiterToAlt": True,
        "loiterClockwise": r.choice([True, False]), "loiterRadius": r.choice([75, 150, 250]),
        "stopTakingPhotos": True, "stopTakingVideo": True, "valueSetIsDistance": True,
    }  # fmt: skip


def varied_plan(k: int) -> tuple[dict, float, str]:
    """Plan ``k`` as a .plan document, its runway heading (deg) and a one-line description."""
    r, frame, heading, unit = random_runway(k)

    def at(along: float, side: float = 0.0) -> list[float]:
        lat, lon = frame.latlon(along * unit[0] - side * unit[1], along * unit[1] + side * unit[0])
        return [lat, lon]

    def simple(command: int, where: list[float], alt: float, p1: float = 0.0) -> dict:
        return {"type": "SimpleItem", "command": command, "frame": 3, "autoContinue": True,
                "params": [p1, 0, 0, None, *where, alt]}  # fmt: skip

    land_along = r.uniform(-100.0, 300.0)
    final = r.uniform(300.0, 1500.0)
    alt = max(min(r.uniform(25.0, 110.0), final * math.tan(math.radians(r.uniform(3, 9)))), 20.0)
    items = [simple(22, at(300.0), 100.0, 15.0)]
    for _ in range(r.randint(1, 2)):
        north, east = r.uniform(-1500.0, 1500.0), r.uniform(-1500.0, 1500.0)
        items.append(simple(16, list(frame.latlon(north, east)), r.uniform(80.0, 150.0)))
    kind = r.choice(["waypoint", "pattern"])
    approach, land = at(land_along - final), at(land_along)
    if kind == "waypoint":
        items += [simple(16, approach, alt), simple(21, land, 0.0)]
    else:
        items.append(landing_pattern(r, land, approach, alt))
    mission = {"items": items, "plannedHomePosition": list(HOME), "version": 2,
               "firmwareType": 12, "vehicleType": 1}  # fmt: skip
    doc = {"fileType": "Plan", "version": 1, "groundStation": "QGroundControl", "mission": mission}
    slope = math.degrees(math.atan2(alt, final))
    return (
        doc,
        heading,
        f"runway {heading:5.1f}° {kind:8} final {final:4.0f} m from {alt:5.1f} m ({slope:.1f}°)",
    )


def _row(s: LandingScore) -> str:
    mark = "on " if s.passed() else "OFF"
    return f"{mark} {s.along_m:+7.1f} / {s.across_m:+5.2f} m, sink {s.sink_m_s:4.2f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plans", type=int, default=30)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--airframe", action="append", help="c172p, J3Cub (default: both)")
    ap.add_argument("--whole-vehicle", action="store_true", help="fly companion sim")
    args = ap.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="varied_landings"))
    if args.whole_vehicle:
        _whole_vehicle(args, folder)
        return
    on: dict[tuple[str, str], int] = {}
    for k in range(args.first, args.first + args.plans):
        doc, heading, what = varied_plan(k)
        path = folder / f"plan{k}.plan"
        path.write_text(json.dumps(doc))
        wind = _crosswind(heading)
        for airframe in args.airframe or ["c172p", "J3Cub"]:
            calm, cross = fly(airframe, path, None), fly(airframe, path, k + 2, wind)
            for name, run in (("calm", calm), ("crosswind", cross)):
                on[airframe, name] = on.get((airframe, name), 0) + run.passed()
            print(f"{k:3} {airframe:6} {what} | calm {_row(calm)} | crosswind {_row(cross)}",
                  flush=True)  # fmt: skip
    for (airframe, name), count in sorted(on.items()):
        print(f"{airframe:6} {name:9}: {count} of {args.plans} on target")


def _whole_vehicle(args: argparse.Namespace, folder: Path) -> None:
    passed: dict[str, int] = {}
    for k in range(args.first, args.first + args.plans):
        doc, heading, what = varied_plan(k)
        path = folder / f"plan{k}.plan"
        path.write_text(json.dumps(doc))
        for airframe in args.airframe or ["c172p", "J3Cub"]:
            weathers = (
                ("calm", (0.0, 0.0, 0.0), "none"),
                ("crosswind", _crosswind(heading), "light"),
            )
            for name, wind, turbulence in weathers:
                flight = Flight(str(path), airframe, wind, turbulence, (), 1, str(SIM_CONFIG),
                                False, 900.0, 10.0)  # fmt: skip
                text, ok = fly_whole_vehicle(flight, path)
                passed[f"{airframe} {name}"] = passed.get(f"{airframe} {name}", 0) + ok
                print(f"{k:3} {airframe:6} {name:9} {text} | {what}", flush=True)
    for row, count in sorted(passed.items()):
        print(f"{row:16}: {count} of {args.plans} passed")


def _crosswind(heading_deg: float) -> tuple[float, float, float]:
    """The crosswind across a runway on ``heading_deg`` (m/s north, east, down)."""
    across = math.radians(heading_deg + 90.0)
    return (CROSSWIND_M_S * math.cos(across), CROSSWIND_M_S * math.sin(across), 0.0)


if __name__ == "__main__":
    main()
