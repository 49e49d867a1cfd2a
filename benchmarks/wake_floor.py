"""What one wake-up costs a Python process here: the floor under every plug-in's CPU.

    uv run python benchmarks/wake_floor.py [--rate 100] [--seconds 10]

An echo process sleeps, is woken by one message, handles it and sleeps again, ``--rate``
times a second; its CPU time (the scheduler's nanosecond count) per wake-up is printed for
two echoes:

- pipe: a blocking ``os.read`` of a byte from a pipe, nothing else: the kernel's wake-up
  and the least Python can do;
- bus: what a plug-in does for one sample, on the project's own bus: a Queue reader's
  ``take`` (the iceoryx2 listener's wait, the sample copied out) and one message published
  back on a writer.

A plug-in that does no work at all still costs this for every wake-up, so the vehicle's
CPU cannot fall below (its wake-ups a second, from ``benchmarks/footprint.py``) x (this).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.process_probes import cpu_seconds, wakeups
from companion.bus.namespace import cleanup_namespace
from companion.bus.node import BusNode
from companion.messages import Imu

ECHO = textwrap.dedent(
    """
    import os, sys
    from companion.bus.node import BusNode
    from companion.messages import Magnetometer
    kind, namespace, pipe_fd = sys.argv[1], sys.argv[2], int(sys.argv[3])
    if kind == "pipe":
        while os.read(pipe_fd, 64):
            pass
    else:
        with BusNode(namespace, "echo") as bus:
            rx, tx = bus.queue_reader("sensors/imu"), bus.writer("sensors/mag")
            os.write(pipe_fd, b"r")  # connected
            while got := rx.take(timeout_s=30.0):
                for msg in got:
                    tx.publish(Magnetometer(t_us=msg.t_us))
    """
)


def echo(kind: str, rate_hz: float, seconds: float) -> tuple[float, float, int]:
    """CPU µs per wake-up of the echo, its wake-ups per message, messages sent."""
    namespace = f"wakefloor{os.getpid()}{kind}"
    to_echo, pipe_w = os.pipe()
    ready_r, ready_w = os.pipe()
    fd = to_echo if kind == "pipe" else ready_w
    proc = subprocess.Popen([sys.executable, "-c", ECHO, kind, namespace, str(fd)], pass_fds=(fd,))
    try:
        with BusNode(namespace, "source") as bus:
            writer, back = bus.writer("sensors/imu"), bus.queue_reader("sensors/mag")
            if kind == "bus":
                os.read(ready_r, 1)
            time.sleep(1.0)  # its imports and first wait are not what is measured
            cpu0, wakes0 = cpu_seconds(proc.pid), wakeups(proc.pid)
            sent, period, start = 0, 1.0 / rate_hz, time.monotonic()
            while time.monotonic() - start < seconds:
                if kind == "pipe":
                    os.write(pipe_w, b"x")
                else:
                    writer.publish(Imu(t_us=sent))
                sent += 1
                time.sleep(max(0.0, start + sent * period - time.monotonic()))
                list(back.drain())
            time.sleep(0.2)  # the last one handled
            cpu = cpu_seconds(proc.pid) - cpu0
            wakes = wakeups(proc.pid) - wakes0
    finally:
        os.close(pipe_w)
        proc.terminate()
        proc.wait(10)
        for f in (to_echo, ready_r, ready_w):
            os.close(f)
        cleanup_namespace(namespace)
    return cpu / max(wakes, 1) * 1e6, wakes / max(sent, 1), sent


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rate", type=float, default=100.0, help="messages a second")
    ap.add_argument("--seconds", type=float, default=10.0)
    args = ap.parse_args()
    print(f"an echo process woken {args.rate:.0f} times a second for {args.seconds:.0f} s:")
    for kind in ("pipe", "bus"):
        us, per_msg, sent = echo(kind, args.rate, args.seconds)
        share = us * args.rate / 1e4
        print(f"  {kind:5s} {us:6.1f} us of CPU per wake-up ({per_msg:.2f} wake-ups a message, "
              f"{sent} messages): {share:.2f} % of a core at {args.rate:.0f} Hz")  # fmt: skip


if __name__ == "__main__":
    main()
