"""IMU sample → Mini SSC frame written, read on the vehicle's own bus, wherever it runs.

    python benchmarks/servo_latency_probe.py NAMESPACE SECONDS  (or until SIGINT)

Run beside a vehicle on the monotonic time base (``companion run``): on the same machine,
or inside the emulated board's root (benchmarks/emulated_board.py copies it there), since
that board's bus is in its own /dev/shm. Each ``actuators/servos`` sample is published
once the frame's bytes are written and carries the stamp of the IMU sample the command
came from (stamped when its first byte arrived); the latency is the arrival here minus
that stamp, this process's wake-up included. Prints one JSON line: p50, p99, max in ms
and the count.
"""

from __future__ import annotations

import json
import sys
import time

from companion.bus.node import BusNode


def main() -> None:
    if len(sys.argv) != 3 or sys.argv[1] in ("-h", "--help"):
        sys.exit(__doc__)
    namespace, seconds = sys.argv[1], float(sys.argv[2])
    latencies_us: list[int] = []
    with BusNode(namespace, "servo_latency_probe") as bus:
        servos = bus.latest_reader("actuators/servos")
        waiter = bus.waiter([servos])
        stop = time.monotonic() + seconds
        try:
            while time.monotonic() < stop:
                waiter.wait(0.05)
                now_us = time.monotonic_ns() // 1000
                latencies_us += [now_us - m.command_t_us for m in servos.drain() if m.command_t_us]
        except KeyboardInterrupt:  # the benchmark ends it with SIGINT when the flight is over
            pass
    # A frame not made from an IMU sample (the neutral one before the first command) has
    # no stamp of this clock: anything over 10 s is one of those, not a latency.
    ms = sorted(v / 1000 for v in latencies_us if 0 < v < 10_000_000)

    def pct(q: float) -> float:
        return ms[min(len(ms) - 1, int(q * len(ms)))] if ms else float("nan")

    print(json.dumps({"p50_ms": pct(0.5), "p99_ms": pct(0.99), "max_ms": pct(1.0), "n": len(ms)}))


if __name__ == "__main__":
    main()
