"""How quickly a pilot on the RC receiver gets the aircraft, and how quickly RC loss acts.

Usage: uv run python benchmarks/pilot_takeover.py [--runs N] [--aircraft c172p]

Flies the square plan in fast lockstep with a scripted pilot (the test's script in
tests/sitl/test_rc_pilot.py) and prints, per run, in simulation time: switch to Manual →
mode change, mode change → the sticks on the servos (and the control period), switch back
→ Auto, receiver silent in Stabilized → Return (FS_LONG_TIMEOUT is 5 s).
"""

from __future__ import annotations

import argparse
import itertools
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from companion.bus.namespace import cleanup_namespace
from companion.messages import FlightMode
from tests.sitl.pilot_logs import first_entry, matches, mode_changes, servo_rows
from tests.sitl.test_rc_pilot import AUTO_AT, MANUAL_AT, SCRIPT, SILENT_AT, SURFACES
from tests.support.vehicle import REPO, companion_env, unique_namespace


def fly(tmp: Path, aircraft: str) -> tuple[float, float, float, float, float]:
    """One run's figures: switch→Manual, Manual→sticks, period, switch→Auto, silent→RTL."""
    (tmp / "pilot.csv").write_text(SCRIPT)
    namespace = unique_namespace("bench")
    cmd = [
        sys.executable, "-m", "companion", "sim", "--speed", "max", "--aircraft", aircraft,
        "--namespace", namespace, "--state-dir", str(tmp / "state"),
        "--plan", str(REPO / "qgc_plans" / "square.plan"), "--start-at", "5",
        "--duration", "135", "--pilot", str(tmp / "pilot.csv"),
        "--servo-log", str(tmp / "servos.csv"), "--link", "udpout://127.0.0.1:9",
    ]  # fmt: skip
    try:
        quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
        subprocess.run(
            cmd, env=companion_env(namespace), cwd=REPO, check=True, timeout=900, **quiet
        )
    finally:
        cleanup_namespace(namespace)
    modes = mode_changes(tmp / "state")
    servos = servo_rows(tmp / "servos.csv")
    period = statistics.median(b[0] - a[0] for a, b in itertools.pairwise(servos))
    manual = first_entry(modes, FlightMode.MANUAL, MANUAL_AT)
    sticks = next(t for t, s in servos if t >= manual and matches(s, SURFACES))
    auto = first_entry(modes, FlightMode.MISSION, AUTO_AT)
    rtl = first_entry(modes, FlightMode.RTL, SILENT_AT)
    return manual - MANUAL_AT, sticks - manual, period, auto - AUTO_AT, rtl - SILENT_AT


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=1)
    parser.add_argument("--aircraft", default="c172p")
    args = parser.parse_args()
    print("run  switch→Manual  Manual→sticks  control period  switch→Auto  silent→Return")
    for run in range(args.runs):
        with tempfile.TemporaryDirectory() as tmp:
            f = fly(Path(tmp), args.aircraft)
        print(f"{run + 1:3d}  {f[0]:10.3f} s  {f[1]:10.3f} s  {f[2]:11.3f} s  "
              f"{f[3]:8.3f} s  {f[4]:10.2f} s")  # fmt: skip


if __name__ == "__main__":
    main()
