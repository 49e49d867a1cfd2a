"""Replay throughput: log seconds per wall second for ``companion replay``'s loop.

Usage: uv run python benchmarks/replay_speed.py [--minutes 10]

Writes a synthetic log (100 Hz IMU, 50 Hz magnetometer, 20 Hz compass, 5 Hz GPS), then
replays it with each navigator exactly as ``companion replay`` does (reading the CSV,
the navigator, writing the 50 Hz estimate), and prints the speed. Target: ≥ 100× real
time for a 100 Hz IMU log.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from companion.sensors.sensorlog import read_sensor_log
from ground.replay.single import replay_log
from ground.simulation.synthetic_flight import CIRCUIT, FlightSpec
from ground.simulation.synthetic_log import synthesize


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    args = parser.parse_args()
    laps = max(1, round(args.minutes * 60 / sum(leg.duration_s for leg in CIRCUIT)))
    with tempfile.TemporaryDirectory() as tmp:
        log = Path(tmp) / "log.csv"
        synthesize(FlightSpec(legs=CIRCUIT * laps, seed=1)).write(log)
        size_mb = log.stat().st_size / 1e6
        started = time.perf_counter()
        rows = sum(1 for _ in read_sensor_log(log))
        read_s = time.perf_counter() - started
        print(f"log: {rows} rows, {size_mb:.1f} MB, {laps} laps; reading alone {read_s:.2f} s")
        for navigator in ("ins_ekf", "gps_compass"):
            summary, _ = replay_log(log, navigator, Path(tmp) / f"{navigator}.csv", 50.0, 11.7)
            print(
                f"{navigator:12s} {summary.log_seconds:7.0f} s of log in "
                f"{summary.wall_seconds:5.2f} s: {summary.speed:6.0f}x real time (target >= 100x)"
            )


if __name__ == "__main__":
    main()
