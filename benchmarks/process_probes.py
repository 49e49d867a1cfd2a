"""What one process costs, read from /proc: its proportional set size and CPU time, and
which processes make up a vehicle (benchmarks/footprint.py)."""

from __future__ import annotations

import os
from pathlib import Path

import psutil


def pss_kib(pid: int) -> int:
    try:
        with open(f"/proc/{pid}/smaps_rollup") as f:
            for line in f:
                if line.startswith("Pss:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return 0


def cpu_ticks(pid: int) -> float:
    """utime + stime of one process, in seconds."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return float("nan")
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def vehicle_pids(root: int) -> list[int]:
    """The vehicle's processes: the root and its descendants, the bridge's subtree left out."""
    try:
        top = psutil.Process(root)
        kids = top.children(recursive=True)
    except psutil.Error:
        return []
    bridge: set[int] = set()
    for p in kids:
        try:
            if "ground.sitl.bridge" in " ".join(p.cmdline()):
                bridge |= {p.pid} | {c.pid for c in p.children(recursive=True)}
        except psutil.Error:
            continue
    return [root] + [p.pid for p in kids if p.pid not in bridge]
