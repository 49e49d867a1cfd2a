"""Take-off, a DO_JUMP loop, then a landing: random plans as a QGroundControl user makes them.

Usage: uv run python benchmarks/jump_landings.py [--plans 12] [--first 0] [--airframe c172p]
       [--calm-only | --crosswind-only] [--closed-loop] [--restart] [--keep DIR]

Plan ``k`` is drawn from a generator seeded with ``k``: NAV_TAKEOFF, a loop of two or
three waypoints 700-1500 m from home at 80-130 m (perhaps a DO_CHANGE_SPEED, perhaps a
NAV_LOITER_TIME or NAV_LOITER_TURNS in it), a DO_JUMP back to the take-off item, the
first or the second waypoint repeated 1-3 times, placed right before the landing or
followed by one more waypoint, then the landing on a runway of random heading: a
waypoint on its line and NAV_LAND (the jump perhaps between the two), or QGroundControl's
landing pattern (DO_LAND_START, LOITER_TO_ALT, NAV_LAND). Each is flown by the whole
vehicle (``companion sim`` in exact lockstep, started at simulated second 10, as
benchmarks/landing.py flies) in calm air and in a 5 m/s crosswind across the runway with
light turbulence; ``--closed-loop`` flies the control laws alone against JSBSim on the true
state instead (tests/support/closed_loop.py), in seconds.

Checked, as a user would see it: the MISSION_ITEM_REACHED sequence the ground station
heard against the plan's (the loop flown exactly its repeat count more times, then the
landing), MISSION_CURRENT never back to 0 after the take-off item, no descent under
``SAFE_SHARE`` of the lowest planned height between the climb and the landing's first
item, the touchdown (15 m along, 2 m across, sink 1.5 m/s: ground/campaign/landing_score.py)
and the disarm; ``own`` is the touchdown across by the vehicle's own navigation solution
(the rest of the truth's is the emulated GPS's wander). ``--restart`` kills the control
plug-in (SIGKILL) once on the loop's second lap: the execution control starts it again,
and the reached sequence must still be the plan's.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import threading
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.jump_flights import (
    ControlKiller,
    fly_closed_loop,
    landing_began,
    last_land,
    last_land_at,
    reached_as_planned,
)
from benchmarks.varied_landings import HOME, _crosswind, landing_pattern, random_runway
from companion.control.mission.plan import checked_plan
from ground.campaign.flight_run import FlightJob, fly_flight
from ground.campaign.landing_score import (
    LandingScore,
    landing_score_for_plan,
    navigation_across,
    read_truth,
)
from ground.campaign.spec import SIM_CONFIG, Flight
from mavlink_dialect import companion as d

SAFE_SHARE = 0.6  # of the lowest planned height: lower than this away from the landing is a fault
START_AT_S = 10.0
MAX_SIM_S = 2000.0


def jump_plan(k: int) -> tuple[dict, float, str]:
    """Plan ``k`` as a .plan document, its runway's heading (deg) and a description."""
    r, frame, heading, unit = random_runway(k)
    items: list[dict] = []

    def add(command: int, ne: tuple[float, float] | None, alt: float, *params: float) -> int:
        lat, lon = frame.latlon(*ne) if ne is not None else (0.0, 0.0)
        p = [*params, 0.0, 0.0, 0.0, 0.0][:4]
        items.append({"type": "SimpleItem", "command": command, "frame": 3 if ne else 2,
                      "autoContinue": True, "doJumpId": len(items) + 1,
                      "params": [*p, lat, lon, alt]})  # fmt: skip
        return len(items)  # its doJumpId

    ids = [add(d.MAV_CMD_NAV_TAKEOFF, (0.0, 300.0), 100.0, 15.0)]
    what = []
    if r.random() < 0.3:
        add(d.MAV_CMD_DO_CHANGE_SPEED, None, 0.0, 0.0, r.uniform(30.0, 34.0), -1.0)
        what.append("speed")
    bearing = r.uniform(0.0, 360.0)
    for n in range(r.choice([2, 3])):
        b = math.radians(bearing + 120.0 * n)
        dist = r.uniform(700.0, 1500.0)
        ids.append(add(d.MAV_CMD_NAV_WAYPOINT, (dist * math.cos(b), dist * math.sin(b)),
                       r.uniform(80.0, 130.0)))  # fmt: skip
    extra = r.choice(["none", "none", "time", "turns"])
    if extra != "none":
        where = r.choice(ids[1:])
        p = items[where - 1]["params"]
        ne = frame.ne(p[4], p[5])
        cmd = d.MAV_CMD_NAV_LOITER_TIME if extra == "time" else d.MAV_CMD_NAV_LOITER_TURNS
        add(cmd, ne, p[6], 30.0 if extra == "time" else 1.0, 0.0, 0.0)
        what.append(f"loiter {extra}")
    target_name = r.choice(["take-off", "first", "first"] + (["second"] if len(ids) > 3 else []))
    target = ids[{"take-off": 0, "first": 1, "second": 2}[target_name]]
    repeats = r.randint(1, 3)
    kind = r.choice(["waypoint", "pattern"])
    place = r.choice(["before landing", "mid"] + (["inside landing"] if kind == "waypoint" else []))

    def jump() -> None:
        add(d.MAV_CMD_DO_JUMP, None, 0.0, float(target), float(repeats))

    if place != "inside landing":
        jump()
    if place == "mid":
        b = math.radians(bearing + 60.0)
        add(d.MAV_CMD_NAV_WAYPOINT, (900.0 * math.cos(b), 900.0 * math.sin(b)), 100.0)
    what.insert(0, f"jump to {target_name} x{repeats} {place}")
    _landing(r, kind, frame, unit, items, jump if place == "inside landing" else None)
    mission = {"items": items, "plannedHomePosition": list(HOME), "version": 2,
               "firmwareType": 12, "vehicleType": 1, "cruiseSpeed": 30,
               "hoverSpeed": 5}  # fmt: skip
    doc = {"fileType": "Plan", "version": 1, "groundStation": "QGroundControl",
           "mission": mission, "geoFence": {"version": 2, "polygons": [], "circles": []},
           "rallyPoints": {"version": 2, "points": []}}  # fmt: skip
    return doc, heading, f"runway {heading:5.1f} {kind:8} " + ", ".join(what)


def _landing(r, kind, frame, unit, items, between) -> None:
    """The landing's items: a waypoint on the runway's line (``between`` adds the jump
    after it) and NAV_LAND, or QGroundControl's landing pattern."""
    land_along = r.uniform(-100.0, 300.0)
    final = r.uniform(500.0, 1200.0)
    alt = max(min(r.uniform(30.0, 80.0), final * math.tan(math.radians(r.uniform(3, 6)))), 25.0)

    def at(along: float) -> list[float]:
        return list(frame.latlon(along * unit[0], along * unit[1]))

    approach, land = at(land_along - final), at(land_along)
    if kind == "waypoint":
        for command, where, height in ((16, approach, alt), (21, land, 0.0)):
            items.append({"type": "SimpleItem", "command": command, "frame": 3,
                          "autoContinue": True, "doJumpId": len(items) + 1,
                          "params": [0, 0, 0, None, *where, height]})  # fmt: skip
            if between is not None and command == 16:
                between()
        return
    items.append(landing_pattern(r, land, approach, alt))


def planned_order(plan: Path) -> list[int]:
    """The navigation items in the order the plan flies them (jumps followed as counted)."""
    items = checked_plan(plan)[0]
    order, seq, done = [], 0, {}
    while seq < len(items):
        item = items[seq]
        if item.command == d.MAV_CMD_DO_JUMP:
            count = done.get(seq, 0)
            done[seq] = count + 1
            seq = round(item.param1) if count < round(item.param2) else seq + 1
            continue
        if item.command in (d.MAV_CMD_DO_CHANGE_SPEED, d.MAV_CMD_DO_LAND_START) or item.x == 0:
            seq += 1
            continue
        order.append(seq)
        seq += 1
    return order


def lowest_between(truth: dict, start_s: float, end_s: float) -> float:
    """The lowest height above the start (m) from ``start_s`` to ``end_s``."""
    t, height = truth["t"], truth["alt"] - truth["alt"][0]
    inside = (t >= start_s) & (t <= end_s)
    return float(height[inside].min()) if inside.any() else math.nan


def judge(plan: Path, folder: Path, row: dict) -> tuple[bool, str]:
    """Whether the flight in ``folder`` did what a user would expect; and how it went."""
    items = checked_plan(plan)[0]
    order = planned_order(plan)
    tl = json.loads((folder / "timeline.json").read_text())
    truth = read_truth(folder / "truth.csv") if (folder / "truth.csv").exists() else None
    score = landing_score_for_plan(truth, items) if truth is not None else LandingScore(False)
    faults = []
    if not reached_as_planned(tl["reached"], order, items):
        faults.append(f"reached {tl['reached']} != {order}")
    seqs = tl["seqs"]
    if back_to_zero(seqs, order):
        faults.append("MISSION_CURRENT back to 0")
    landing = _landing_first(items, order)
    low = math.nan
    began = landing_began(seqs, landing, last_land(items, order))
    if truth is not None and began is not None and order[1] in seqs:
        climbed = tl["seq_ms"][seqs.index(order[1])] / 1000.0
        low = lowest_between(truth, climbed + 20.0, tl["seq_ms"][began] / 1000.0)
    if not low >= SAFE_SHARE * least_planned(items, order):
        faults.append(f"down to {low:.0f} m before the landing")
    if not score.passed():
        faults.append("landing off target")
    if row.get("armed_at_end") is not False:
        faults.append("not disarmed")
    if row["status"] != "ok":
        faults.append(row["error"])
    est = navigation_across(folder / "truth.csv", plan, score) if truth is not None else math.nan
    text = (f"{score.along_m:+7.1f} / {score.across_m:+5.2f} m (own {est:+5.2f}) "
            f"sink {score.sink_m_s:4.2f} low {low:4.0f} m")  # fmt: skip
    return not faults, text + ("  " + "; ".join(faults) if faults else "")


def back_to_zero(seqs: list[int], order: list[int]) -> bool:
    """Whether MISSION_CURRENT went back to 0 after it left it (and no jump flies item 0)."""
    first = next((k for k, s in enumerate(seqs) if s != 0), len(seqs))
    return 0 in seqs[first:] and 0 not in order[1:]


def least_planned(items: list, order: list[int]) -> float:
    """The lowest height the plan flies at before its landing begins (m above home)."""
    last = last_land_at(items, order)
    if last < 0:
        raise ValueError("the plan flies no NAV_LAND")
    return min(items[s].z for s in order[1 : last - 1])


def _landing_first(items: list, order: list[int]) -> int:
    """The first item of the landing: the one flown before the last NAV_LAND."""
    at = last_land_at(items, order)
    return order[at - 1] if at >= 0 else -1


def fly_whole(plan: Path, airframe: str, weather: tuple, out: Path, restart: bool) -> tuple:
    wind, turbulence = weather
    flight = Flight(str(plan), airframe, wind, turbulence, (), 1, str(SIM_CONFIG), False,
                    MAX_SIM_S, START_AT_S)  # fmt: skip
    killer = ControlKiller(plan) if restart else None
    if killer is not None:
        threading.Thread(target=killer.run, daemon=True).start()
    try:
        row = fly_flight(FlightJob(flight, str(out), timeout_s=2400.0))
    finally:
        if killer is not None:
            killer.stop.set()
    ok, text = judge(plan, out / flight.flight_id, row)
    if killer is not None:
        text += f" | control killed at item {killer.killed_at}"
        ok = ok and killer.killed_at is not None
    return ok, text


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plans", type=int, default=12)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--airframe", action="append", help="c172p, J3Cub (default: both)")
    ap.add_argument("--calm-only", action="store_true")
    ap.add_argument("--crosswind-only", action="store_true")
    ap.add_argument("--closed-loop", action="store_true", help="the control laws alone")
    ap.add_argument("--restart", action="store_true", help="kill the controller mid-loop")
    ap.add_argument("--keep", type=Path, help="keep each flight's folder here")
    args = ap.parse_args()
    folder = args.keep or Path(tempfile.mkdtemp(prefix="jump_landings"))
    folder.mkdir(parents=True, exist_ok=True)
    passed: dict[str, int] = {}
    for k in range(args.first, args.first + args.plans):
        doc, heading, what = jump_plan(k)
        path = folder / f"jump{k}.plan"
        path.write_text(json.dumps(doc))
        weathers = {"calm": ((0.0, 0.0, 0.0), "none"),
                    "crosswind": (_crosswind(heading), "light")}  # fmt: skip
        for airframe in args.airframe or ["c172p", "J3Cub"]:
            for name, weather in weathers.items():
                if (args.calm_only and name != "calm") or (
                    args.crosswind_only and name != "crosswind"
                ):
                    continue
                if args.closed_loop:
                    ok, text = fly_closed_loop(path, airframe, weather, k)
                else:
                    ok, text = fly_whole(path, airframe, weather, folder, args.restart)
                passed[f"{airframe} {name}"] = passed.get(f"{airframe} {name}", 0) + ok
                mark = "ok  " if ok else "FAIL"
                print(f"{k:3} {airframe:6} {name:9} {mark} {text} | {what}", flush=True)
    for row, count in sorted(passed.items()):
        print(f"{row:16}: {count} of {args.plans} passed")


if __name__ == "__main__":
    main()
