"""What one process costs, read from /proc: its proportional set size, CPU time and
wake-ups, and which processes make up a vehicle (benchmarks/footprint.py)."""

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


def cpu_seconds(pid: int) -> float:
    """CPU time of one process, all its threads, in seconds: the scheduler's nanosecond
    count (/proc/PID/task/*/schedstat), not the 10 ms ticks of /proc/PID/stat, which
    cannot tell 0.02 % of a core from 0.05 % over 20 s."""
    try:
        total_ns = 0
        for tid in os.listdir(f"/proc/{pid}/task"):
            total_ns += int(Path(f"/proc/{pid}/task/{tid}/schedstat").read_text().split()[0])
        return total_ns / 1e9
    except (OSError, ValueError, IndexError):
        return float("nan")


def wakeups(pid: int) -> int:
    """How many times the process's threads have gone to sleep and so been woken again
    (voluntary context switches), all threads together; 0 when it is gone."""
    count = 0
    try:
        for tid in os.listdir(f"/proc/{pid}/task"):
            for line in Path(f"/proc/{pid}/task/{tid}/status").read_text().splitlines():
                if line.startswith("voluntary_ctxt_switches"):
                    count += int(line.split()[1])
    except (OSError, ValueError):
        return 0
    return count


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
            if "bridges.jsbsim" in " ".join(p.cmdline()):
                bridge |= {p.pid} | {c.pid for c in p.children(recursive=True)}
        except psutil.Error:
            continue
    return [root] + [p.pid for p in kids if p.pid not in bridge]
