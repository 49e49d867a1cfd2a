"""CPU and wake-ups of the vehicle per simulated second, each process apart.

    uv run python benchmarks/wake_budget.py [--seconds 30] [--repeat 2] [--config FILE]

Flies ``companion sim`` in real time on the square mission (airborne, armed at simulated
second ``ARM_AT_S``) and, over a fixed stretch of simulated time (``--seconds`` from
``FLYING_AFTER_S`` after arming), reads from ``/proc`` every vehicle process's CPU time
(utime + stime of ``/proc/PID/stat``: the process with all its threads; the simulator
bridge is left out) and its wake-ups (voluntary context switches of all its threads,
``/proc/PID/task/*/status``). Both are divided by the simulated seconds flown, not by the
wall clock: a busy machine that slows the simulation slows the vehicle's work with it, so
the figures hold on a loaded machine where a share of a core does not.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks.footprint import ARM_AT_S, FLYING_AFTER_S, Vehicle, use_bytecode  # noqa: E402
from benchmarks.process_probes import wakeups  # noqa: E402

TICK_S = 1.0 / os.sysconf("SC_CLK_TCK")


def utime_stime(pid: int) -> float:
    """Seconds of CPU the process (every thread) has used: utime + stime."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return float("nan")
    fields = text[text.rindex(")") + 2 :].split()  # after the command name, from field 3
    return (int(fields[11]) + int(fields[12])) * TICK_S


def fly(seconds: float, config: str | None) -> tuple[dict[str, float], dict[str, float], float]:
    """CPU seconds and wake-ups of each process per simulated second, and sim/real."""
    tmp = Path(tempfile.mkdtemp(prefix="wake_budget"))
    namespace = f"wb{os.getpid()}_{int(time.time() * 1000) % 100000}"
    cmd = [sys.executable, "-m", "companion", "sim", "--plan", "qgc_plans/square.plan",
           "--airborne", "--start-at", str(ARM_AT_S), "--namespace", namespace,
           "--state-dir", str(tmp / "state"), "--link", "udpout://127.0.0.1:9",
           "--log-level", "ERROR", *(["--config", config] if config else [])]  # fmt: skip
    v = Vehicle(cmd, namespace, None)
    try:
        v.vehicle_up()
        start = ARM_AT_S + FLYING_AFTER_S
        v.wait_sim(start)
        pids = v.labelled()
        before = {n: (utime_stime(p), wakeups(p)) for n, p in pids.items()}
        sim0, wall0 = v.sim_s(), time.monotonic()
        v.wait_sim(start + seconds)
        after = {n: (utime_stime(p), wakeups(p)) for n, p in pids.items()}
        sim, wall = v.sim_s() - sim0, time.monotonic() - wall0
    finally:
        v.stop()
    cpu = {n: (after[n][0] - before[n][0]) / sim for n in pids}
    wakes = {n: (after[n][1] - before[n][1]) / sim for n in pids}
    return cpu, wakes, sim / wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=30.0, help="simulated seconds measured")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--config", help="vehicle config (default: companion sim's own)")
    args = ap.parse_args()
    use_bytecode()
    load0 = os.getloadavg()[0]
    runs = [fly(args.seconds, args.config) for _ in range(args.repeat)]
    names = sorted({n for cpu, _, _ in runs for n in cpu})
    print(f"companion sim, square mission, {args.seconds:.0f} simulated s from "
          f"{ARM_AT_S + FLYING_AFTER_S:.0f} s; median of {args.repeat}; load "
          f"{load0:.1f} -> {os.getloadavg()[0]:.1f}; sim/real "
          f"{statistics.median(r[2] for r in runs):.3f}")  # fmt: skip
    print(f"{'process':<14}{'CPU ms/sim s':>13}{'wakes/sim s':>13}")
    for name in names:
        cpu = statistics.median(r[0].get(name, 0.0) for r in runs) * 1000
        wakes = statistics.median(r[1].get(name, 0.0) for r in runs)
        print(f"{name:<14}{cpu:13.1f}{wakes:13.1f}")
    total_cpu = statistics.median(sum(r[0].values()) for r in runs) * 1000
    total_wakes = statistics.median(sum(r[1].values()) for r in runs)
    print(f"{'total':<14}{total_cpu:13.1f}{total_wakes:13.1f}")


if __name__ == "__main__":
    main()
