"""Two-process round-trip latency of the bus patterns, and the CPU of an idle wait.

Usage: uv run python benchmarks/bus_latency.py [--samples N]

A ping goes from this process to an echo process and back, both sides sleeping on the
channel's event (no polling): Queue uses sensors/imu → sensors/mag, Latest uses
nav/state → sim/truth. Target on the 2-core dev machine: p50 ≤ 100 µs, p99 ≤ 300 µs.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import textwrap
import time

import numpy as np
import psutil

from companion.bus.namespace import cleanup_namespace
from companion.bus.node import BusNode
from companion.messages import Imu, NavState

ECHO = textwrap.dedent(
    """
    import sys
    from companion.bus.node import BusNode
    from companion.messages import Imu, Magnetometer, NavState
    ns, pattern, count = sys.argv[1], sys.argv[2], int(sys.argv[3])
    with BusNode(ns, "echo") as bus:
        if pattern == "queue":
            rx, tx = bus.queue_reader("sensors/imu"), bus.writer("sensors/mag")
            done = 0
            while done < count:
                got = rx.take(timeout_s=5.0)
                if not got:
                    break  # the benchmark went away
                for m in got:
                    tx.publish(Magnetometer(t_us=m.t_us))
                    done += 1
        elif pattern == "latest":
            rx, tx = bus.latest_reader("nav/state"), bus.writer("sim/truth")
            for _ in range(count):
                m = rx.wait(5.0)
                if m is None:
                    break
                tx.publish(NavState(t_us=m.t_us))
        else:  # idle: wait on a channel nobody writes
            rx = bus.queue_reader("sensors/baro")
            for _ in range(count):
                rx.take(timeout_s=1.0)
    """
)


def spawn(ns: str, pattern: str, count: int) -> subprocess.Popen[bytes]:
    return subprocess.Popen([sys.executable, "-c", ECHO, ns, pattern, str(count)])


def round_trips(bus: BusNode, ns: str, pattern: str, samples: int) -> np.ndarray:
    warmup = 200
    if pattern == "queue":
        tx, rx = bus.writer("sensors/imu"), bus.queue_reader("sensors/mag")
    else:
        tx, rx = bus.writer("nav/state"), bus.latest_reader("sim/truth")
    echo = spawn(ns, pattern, samples + warmup)
    try:
        return _measure(tx, rx, pattern, samples, warmup)
    finally:
        echo.kill()
        echo.wait()


def _measure(tx, rx, pattern: str, samples: int, warmup: int) -> np.ndarray:
    time.sleep(1.0)  # let the echo process connect
    rtt = []
    for i in range(samples + warmup):
        t0 = time.perf_counter_ns()
        tx.publish(Imu(t_us=i) if pattern == "queue" else NavState(t_us=i))
        got = rx.take(timeout_s=2.0) if pattern == "queue" else rx.wait(2.0)
        t1 = time.perf_counter_ns()
        if not got:
            raise RuntimeError(f"{pattern}: echo {i} lost")
        if i >= warmup:
            rtt.append((t1 - t0) / 1000.0)
    return np.array(rtt)


def idle_cpu(ns: str, seconds: float) -> float:
    proc = spawn(ns, "idle", int(seconds) + 2)
    time.sleep(1.0)
    ps = psutil.Process(proc.pid)
    before, t0 = ps.cpu_times(), time.monotonic()
    time.sleep(seconds)
    after, elapsed = ps.cpu_times(), time.monotonic() - t0
    proc.kill()
    proc.wait()
    return (after.user + after.system - before.user - before.system) / elapsed * 100.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=5000)
    parser.add_argument("--idle-seconds", type=float, default=5.0)
    args = parser.parse_args()
    ns = f"bench{os.getpid()}"
    print(
        f"bus round trip between two processes, {args.samples} samples each ({os.cpu_count()} CPUs)"
    )
    try:
        with BusNode(ns, "bench") as bus:
            for pattern in ("queue", "latest"):
                rtt = round_trips(bus, ns, pattern, args.samples)
                p50, p99, pmax = np.percentile(rtt, [50, 99, 100])
                verdict = "OK" if p50 <= 100 and p99 <= 300 else "ABOVE TARGET"
                print(
                    f"  {pattern:6}  p50 {p50:7.1f} µs   p99 {p99:7.1f} µs   max {pmax:8.1f} µs"
                    f"   (target p50 ≤ 100, p99 ≤ 300: {verdict})"
                )
        cpu = idle_cpu(ns, args.idle_seconds)
        print(f"  idle wait CPU over {args.idle_seconds:.0f} s: {cpu:.3f} % of one core")
    finally:
        cleanup_namespace(ns)


if __name__ == "__main__":
    main()
