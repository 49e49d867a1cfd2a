"""From an IMU sample's first byte on the wire to the servo bytes and to ATTITUDE.

    uv run python benchmarks/latency.py [--seconds 60] [--config CONFIG.toml]

Flies ``companion sim`` in real time on a mission, with the vehicle on the hardware time
base (monotonic µs, as on an aircraft) so that every ``t_us`` is a wall-clock stamp: the
IMU driver stamps a sample when its first byte arrives. A subscriber process (this one)
notes when each stage's message appears: (a) nav/state, (b) control/actuators, (c) the
servo output the Mini SSC plug-in publishes once the frame's bytes are written, (d)
ATTITUDE on UDP (matched to the navigation state whose attitude it carries). Each
latency is the arrival time minus the IMU sample's stamp; the subscriber's own wake-up
(~0.1 ms) is included (it sleeps on the bus and the UDP socket together). Where the system
allows it the subscriber runs under SCHED_FIFO above the vehicle's flight chain, so that on
a busy machine its own wait for a CPU is not counted as the vehicle's; the servo stage is
also given as the servo output stamped it (its ``t_us``, taken once the frame is written),
which no subscriber delays. Prints p50, p99 and max per stage, the control period's jitter
and the stalls over 20 ms.
"""

from __future__ import annotations

import argparse
import os
import socket
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from companion.bus.namespace import cleanup_namespace  # noqa: E402
from companion.bus.node import BusNode  # noqa: E402
from mavlink_dialect import companion as m  # noqa: E402

WARM_UP_S = 15.0
STALL_US = 20_000
OBSERVER_FIFO = 20  # above the flight chain's realtime_priority (10 by default)


SIM_CONFIG = REPO / "companion" / "configs" / "sim.toml"


def vehicle_config(tmp: Path, source: Path = SIM_CONFIG) -> Path:
    """A shipped simulation vehicle on the monotonic (hardware) time base."""
    text = source.read_text()
    path = tmp / "latency.toml"
    path.write_text(text.replace('clock = "sim"', 'clock = "monotonic"'))
    return path


def start_sim(
    tmp: Path, namespace: str, port: int, seconds: float, source: Path = SIM_CONFIG
) -> subprocess.Popen[bytes]:
    cmd = [
        sys.executable, "-m", "companion", "sim", "-c", str(vehicle_config(tmp, source)),
        "--plan", "qgc_plans/square.plan", "--airborne", "--start-at", "2",
        "--duration", str(seconds + WARM_UP_S + 5), "--namespace", namespace,
        "--state-dir", str(tmp / "state"), "--link", f"udpout://127.0.0.1:{port}",
        "--log-level", "ERROR",
    ]  # fmt: skip
    return subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.DEVNULL)


def f32(x: float) -> float:
    return struct.unpack("<f", struct.pack("<f", x))[0]


class Stages:
    """Arrival minus IMU stamp, in µs, per stage."""

    def __init__(self) -> None:
        stages = ("nav", "actuators", "servos", "servos_stamped", "att")
        self.lat: dict[str, list[int]] = {k: [] for k in stages}
        self.by_attitude: dict[tuple[float, float], int] = {}
        self.control_arrivals: list[int] = []
        self.observer = ""

    def note(self, stage: str, now_us: int, t_us: int) -> None:
        if t_us > 0:
            self.lat[stage].append(now_us - t_us)


def listen(port: int) -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", port))
    sock.setblocking(False)
    return sock


def observe_first() -> str:
    """This thread under SCHED_FIFO above the vehicle when the system allows it."""
    try:
        policy = os.SCHED_FIFO | os.SCHED_RESET_ON_FORK
        os.sched_setscheduler(0, policy, os.sched_param(OBSERVER_FIFO))
    except OSError:
        return "normal scheduling (SCHED_FIFO refused)"
    return f"SCHED_FIFO {OBSERVER_FIFO}"


def measure(namespace: str, sock: socket.socket, seconds: float) -> Stages:
    stages, parser = Stages(), m.MAVLink(None)
    stages.observer = observe_first()
    with BusNode(namespace, "latency") as bus:
        nav = bus.latest_reader("nav/state")
        act = bus.queue_reader("control/actuators")
        servos = bus.latest_reader("actuators/servos")
        waiter = bus.waiter([nav, act, servos])
        start = time.monotonic()
        while time.monotonic() - start < WARM_UP_S + seconds:
            # The UDP socket too: woken only by the bus, ATTITUDE was noted at the next bus
            # sample or the 2 ms timeout, up to 2 ms after it arrived.
            waiter.wait_with_fds(0.002, [sock.fileno()], fds_key=sock)
            now = time.monotonic_ns() // 1000
            counting = time.monotonic() - start > WARM_UP_S
            for msg in nav.drain():
                stages.by_attitude[(f32(msg.roll_rad), f32(msg.pitch_rad))] = msg.t_us
                if counting:
                    stages.note("nav", now, msg.t_us)
            for msg in act.drain():
                if counting:
                    stages.note("actuators", now, msg.t_us)
                    stages.control_arrivals.append(now)
            for msg in servos.drain():
                if counting:
                    stages.note("servos", now, msg.command_t_us)
                    stages.note("servos_stamped", msg.t_us, msg.command_t_us)
            read_udp(sock, parser, stages, now, counting)
    return stages


def read_udp(sock, parser, stages: Stages, now: int, counting: bool) -> None:
    while True:
        try:
            data = sock.recv(65536)
        except BlockingIOError:
            return
        for msg in parser.parse_buffer(data) or []:
            if msg.get_type() == "ATTITUDE" and counting:
                t_us = stages.by_attitude.get((msg.roll, msg.pitch), 0)
                stages.note("att", now, t_us)


def summary(name: str, values: list[int]) -> str:
    if not values:
        return f"{name:<40} no samples"
    a = np.array(values) / 1000.0
    p50, p99 = np.percentile(a, [50, 99])
    stalls = int(np.sum(a > STALL_US / 1000))
    spread = f"p50 {p50:6.2f}  p99 {p99:6.2f}  max {a.max():7.2f} ms"
    return f"{name:<40} {spread}  (n={len(a)}, >20 ms: {stalls})"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument(
        "--config", type=Path, default=SIM_CONFIG, help="vehicle config (default sim.toml)"
    )
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="latency"))
    namespace, sock = f"lat{os.getpid()}", listen(0)
    sim = start_sim(tmp, namespace, sock.getsockname()[1], args.seconds, args.config)
    try:
        stages = measure(namespace, sock, args.seconds)
    finally:
        sim.terminate()
        sim.wait(timeout=30)
        cleanup_namespace(namespace)
    print(
        f"companion sim in real time, mission flying, {args.seconds:.0f} s after {WARM_UP_S:.0f} s;"
        f" the subscriber at {stages.observer}"
    )
    print(summary("IMU first byte -> nav/state", stages.lat["nav"]))
    print(summary("IMU first byte -> control/actuators", stages.lat["actuators"]))
    print(summary("IMU first byte -> Mini SSC frame written", stages.lat["servos"]))
    print(summary("  the same, as the servo output stamped it", stages.lat["servos_stamped"]))
    print(summary("IMU first byte -> ATTITUDE on UDP", stages.lat["att"]))
    periods = np.diff(stages.control_arrivals) / 1000.0
    if len(periods):
        print(f"control period: median {np.median(periods):.2f} ms, std {periods.std():.2f} ms, "
              f"p99 {np.percentile(periods, 99):.2f} ms, max {periods.max():.2f} ms")  # fmt: skip


if __name__ == "__main__":
    main()
