"""Hardware in the loop against exact lockstep: the same plan, scored the same way.

Usage: uv run python benchmarks/hil_tracking.py [--plan short_leg.plan] [--aircraft c172p]
       [--wind N,E,D] [--turbulence none]

It flies the plan twice and prints one row each from the simulator's truth (the campaign's
score, ground/campaign/scoring.py: cross-track RMS / p95, height RMS, airspeed RMS over the
straight parts of the legs):
- ``hil``: ``companion hil --ptys DIR`` and ``companion run`` with the shipped HIL config,
  started apart, joined only by ptys and UDP, in real time, the mission uploaded, armed and
  started by MAVSDK (tests/support/hil.py, the test's own set-up);
- ``exact``: ``companion sim --exact --start-at 10`` with the plan preloaded
  (ground/campaign/flight_run.py), the same flight run after run.
For the HIL flight it also prints what each line carried and dropped, from the
simulator's last report. Real time: the HIL row takes as long as the flight.
"""

from __future__ import annotations

import argparse
import asyncio
import re
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from companion.navigation.estimate_csv import read_estimate  # noqa: E402
from ground.campaign.flight_run import FlightJob, fly_flight  # noqa: E402
from ground.campaign.scoring import score_track  # noqa: E402
from ground.campaign.spec import PLANS, SIM_CONFIG, Flight  # noqa: E402
from tests.support.hil import HilRun  # noqa: E402
from tests.support.mavsdk_flight import fly_plan  # noqa: E402

START_AT_S = 10.0


def _hil(plan: Path, aircraft: str, wind: str, turbulence: str) -> tuple[dict, str]:
    with tempfile.TemporaryDirectory() as tmp:
        args = ["--aircraft", aircraft, "--wind", wind, "--turbulence", turbulence]
        run = HilRun(Path(tmp), *args, "--duration", "1200")
        try:
            seen = asyncio.run(fly_plan(run.port, str(plan), 1100.0))
        finally:
            run.stop()
        wind_ned = tuple(float(v) for v in wind.split(","))
        score = score_track(read_estimate(run.truth), plan, aircraft, wind_ned)
        reports = [ln for ln in run.log("hil").splitlines() if " out: " in ln]
        row = {"completed": seen["finished"], **score.as_row()}
        return row, re.sub(r".*INFO ", "", reports[-1]) if reports else ""


def _exact(plan: Path, aircraft: str, wind: str, turbulence: str) -> dict:
    wind_ned = tuple(float(v) for v in wind.split(","))
    flight = Flight(str(plan), aircraft, wind_ned, turbulence, (), 1, str(SIM_CONFIG),
                    False, 900.0, START_AT_S)  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        return fly_flight(FlightJob(flight, tmp, timeout_s=900.0))


def _row(pace: str, r: dict) -> str:
    return (
        f"{pace:6} {r['completed']!s:5} {r['xtrack_rms_m']:7.2f} {r['xtrack_p95_m']:7.2f} "
        f"{r['alt_rms_m']:8.2f} {r['airspeed_rms_m_s']:8.2f} {r['samples']:6d}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plan", default="short_leg.plan")
    ap.add_argument("--aircraft", default="c172p")
    ap.add_argument("--wind", default="0,0,0", help="N,E,D m/s")
    ap.add_argument("--turbulence", default="none")
    args = ap.parse_args()
    plan = (PLANS / args.plan) if not Path(args.plan).exists() else Path(args.plan).resolve()
    conditions = (plan, args.aircraft, args.wind, args.turbulence)
    print(f"{args.aircraft} {plan.name} wind {args.wind} turbulence {args.turbulence}")
    print(f"{'pace':6} {'done':5} {'xt rms':>7} {'xt p95':>7} {'alt rms':>8} {'spd rms':>8} n")
    hil, lines = _hil(*conditions)
    print(_row("hil", hil), flush=True)
    print(_row("exact", _exact(*conditions)), flush=True)
    print(f"hil lines at the end: {lines}")


if __name__ == "__main__":
    main()
