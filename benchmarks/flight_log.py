"""The flight logger's cost: bytes per second of log and its CPU, at the default channels.

Usage: uv run python benchmarks/flight_log.py [--seconds 60] [--speed 1]

Flies ``companion sim --airborne --plan qgc_plans/square.plan --start-at 2`` (the shipped
config, whose ``system.logger`` records the default channels) and reads the armed flight's
ULog back with pyulog: its size over the logged sensor time, samples per topic, and the
logger's own ``cpu_pct`` and ``dropped`` from the health table it logged.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from pyulog import ULog

REPO = Path(__file__).resolve().parents[1]


def _row_of(health: dict, name: str) -> int | None:
    for i in range(32):
        key = f"plugins[{i}].name[0]"
        if key not in health:
            return None
        chars = [int(health[f"plugins[{i}].name[{j}]"][-1]) & 0xFF for j in range(24)]
        if bytes(chars).split(b"\0")[0].decode() == name:
            return i
    return None


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--speed", default="1")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        state = Path(tmp) / "state"
        cmd = [sys.executable, "-m", "companion", "sim", "--duration", str(args.seconds)]
        cmd += ["--plan", "qgc_plans/square.plan", "--airborne", "--start-at", "2"]
        cmd += ["--speed", args.speed, "--state-dir", str(state), "-n", f"bflog{os.getpid()}"]
        cmd += ["--link", "udpout://127.0.0.1:47997"]
        subprocess.run(cmd, cwd=REPO, check=True, capture_output=True)
        path = sorted((state / "logs").glob("*_armed.ulg"))[-1]
        ulog = ULog(str(path))
        imu = ulog.get_dataset("sensors_imu").data["timestamp"]
        span_s = (int(imu[-1]) - int(imu[0])) / 1e6
        size = path.stat().st_size
        print(f"{path.name}: {size} bytes over {span_s:.1f} s of sensor time")
        print(f"  {size / span_s / 1000:.1f} kB/s of (simulated) flight")
        for data in sorted(ulog.data_list, key=lambda d: d.name):
            n = len(data.data["timestamp"])
            print(f"  {data.name:22s} {n:7d} samples  {n / span_s:7.1f}/s")
        health = ulog.get_dataset("system_health").data
        row = _row_of(health, "logger")
        if row is not None:
            cpu = np.asarray(health[f"plugins[{row}].cpu_pct"], dtype=float)
            dropped = int(health[f"plugins[{row}].dropped"][-1])
            print(f"  logger CPU: mean {cpu[1:].mean():.1f} %, max {cpu.max():.1f} % of a core")
            print(f"  logger dropped: {dropped} samples (last health table logged)")


if __name__ == "__main__":
    main()
