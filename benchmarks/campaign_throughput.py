"""Simulated flight-seconds per wall-second: fleets of 1, 2 and 4 vehicles, and a campaign.

Usage: uv run python benchmarks/campaign_throughput.py [--seconds 120] [--flights 8]

Fleets: ``companion sim --count N --speed max --airborne --duration SECONDS`` (every
vehicle whole: drivers, ins_ekf, commander, link; disarmed, so gliding); the figure is the
sum of the vehicles' simulated seconds over the fleet's wall time from launch to exit
(start-up included) and over the bridges' own running time (start-up excluded).
Campaign: FLIGHTS flights of qgc_plans/short_leg.plan (calm and 4 m/s crosswind, seeds
1..) on a local Ray instance with every CPU, from launch to the report, start-up included.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from ground.campaign.runner import run_campaign  # noqa: E402
from ground.campaign.spec import load_spec  # noqa: E402

RESULT = re.compile(r"simulated ([\d.]+) s in ([\d.]+) s wall")
SPEC = """
[campaign]
name = "throughput"
mode = "random"
samples = {flights}

[flights]
plans = ["short_leg.plan"]
winds = [[0, 0, 0], [0, 4, 0]]
seeds = {seeds}
"""


def fleet(count: int, seconds: float) -> tuple[float, float, float]:
    """(simulated seconds in all, wall seconds from launch, longest bridge run)."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [
            sys.executable, "-m", "companion", "sim", "--count", str(count), "--speed", "max",
            "--airborne", "--duration", f"{seconds:g}", "--state-dir", tmp,
            "--link", "udpout://127.0.0.1:9", "--api-port-base", "0",
            "--namespace", f"tput{os.getpid()}n{count}", "--log-level", "WARNING",
        ]  # fmt: skip
        started = time.monotonic()
        done = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, check=True)
        wall = time.monotonic() - started
        # One vehicle logs to the terminal; a fleet's vehicles each to STATE_DIR/v<i>/sim.log.
        texts = [done.stdout + done.stderr] + [p.read_text() for p in Path(tmp).glob("v*/sim.log")]
    found = [m for t in texts for m in RESULT.finditer(t)]
    if len(found) != count:
        raise SystemExit(f"{count} vehicles: only {len(found)} reported their run")
    sim = sum(float(m.group(1)) for m in found)
    return sim, wall, max(float(m.group(2)) for m in found)


def campaign(flights: int) -> tuple[float, float, int]:
    """(simulated seconds in all, wall seconds, failed flights)."""
    with tempfile.TemporaryDirectory() as tmp:
        spec_path = Path(tmp) / "throughput.toml"
        seeds = list(range(1, (flights + 1) // 2 + 1))
        spec_path.write_text(SPEC.format(flights=flights, seeds=seeds))
        spec = load_spec(spec_path)
        started = time.monotonic()
        outcome = run_campaign(spec, Path(tmp) / "out", cpus=os.cpu_count())
        wall = time.monotonic() - started
        import csv

        with outcome.results.open() as f:
            rows = list(csv.DictReader(f))
    return sum(float(r["sim_s"] or 0) for r in rows), wall, outcome.failed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=120.0, help="simulated seconds per vehicle")
    ap.add_argument("--flights", type=int, default=8)
    ap.add_argument("--counts", default="1,2,4")
    args = ap.parse_args()
    print(f"CPUs: {os.cpu_count()}")
    print(f"{'run':24} {'sim s':>8} {'wall s':>8} {'sim s / wall s':>15} {'excl. start-up':>15}")
    for count in (int(c) for c in args.counts.split(",")):
        sim, wall, running = fleet(count, args.seconds)
        print(f"{f'fleet of {count}':24} {sim:8.0f} {wall:8.1f} {sim / wall:15.1f} "
              f"{sim / running:15.1f}", flush=True)  # fmt: skip
    sim, wall, failed = campaign(args.flights)
    name = f"campaign of {args.flights} ({failed} failed)"
    print(f"{name:24} {sim:8.0f} {wall:8.1f} {sim / wall:15.1f} {'':>15}", flush=True)


if __name__ == "__main__":
    main()
