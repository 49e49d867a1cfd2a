"""The serial sensor plug-ins fed as a USB serial adapter feeds them: a sentence in pieces.

    uv run python benchmarks/serial_pieces.py [--seconds 10]

On a real board a sentence does not arrive whole, as the simulator's ptys hand it over: a
USB serial adapter passes on what the line has carried every millisecond in low-latency
mode (the IMU's port) and every 16 ms otherwise (an FTDI's default latency timer: the GPS
and the compass). A vehicle runs the VectorNav IMU (115200 baud, 40 sentences a second),
the OS-3000 compass (19200 baud, 20 Hz) and the NMEA GPS (4800 baud, a GGA and an RMC
once a second) on three ptys, and a thread per device writes each sentence in those
pieces on the line's own schedule (a writer running late catches up at once, as the line
would have carried the bytes anyway). Printed per device: sentences written, samples
published, the plug-in's steps (each a wake-up and a read) per sample, its process's CPU
(a share of a core, over the writing; each plug-in is a process here), and the delay from
a sentence's last piece written to its sample on the bus (p50 / p99 / max; this process's
own wake-up included).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks.process_probes import cpu_seconds  # noqa: E402
from tests.support.configs import plugin, vehicle_config  # noqa: E402
from tests.support.hostile_sentences import compass_valid, imu_valid, nmea_valid  # noqa: E402
from tests.support.pty import Pty  # noqa: E402
from tests.support.vehicle import Vehicle  # noqa: E402


class _Pick:
    """A stand-in for ``random.Random`` that always draws ``value`` (which sentence)."""

    def __init__(self, value: float) -> None:
        self.value = value

    def random(self) -> float:
        return self.value


GGA_RMC = [nmea_valid(_Pick(0.0)), nmea_valid(_Pick(0.9))]  # type: ignore[arg-type]
# name: plug-in, baud, samples a second, ms of line a piece carries, channel, the sentences
# of one sample (a fix is a GGA and an RMC)
DEVICES = {
    "imu": ("sensors.serial_imu", 115_200, 40.0, 1, "sensors/imu", [imu_valid(_Pick(0))]),  # type: ignore[arg-type]
    "compass": ("sensors.os3000", 19_200, 20.0, 16, "sensors/compass", [compass_valid(_Pick(0))]),  # type: ignore[arg-type]
    "gps": ("sensors.nmea_gps", 4_800, 1.0, 16, "sensors/gps", GGA_RMC),
}


def pieces(text: str, baud: int, piece_ms: int) -> list[tuple[float, bytes]]:
    """``text`` cut into what the line carries in each ``piece_ms``, with when each piece
    is whole (seconds from the sentence's first byte)."""
    data, per_s = text.encode(), baud / 10
    size = max(1, round(per_s * piece_ms / 1000))
    return [
        (min(i + size, len(data)) / per_s, data[i : i + size]) for i in range(0, len(data), size)
    ]


def feed(pty: Pty, device: tuple, seconds: float, ends: list[float]) -> None:
    """Write the device's samples in pieces for ``seconds``; note when each one ended."""
    _, baud, rate_hz, piece_ms, _, sentences = device
    start, n = time.monotonic(), 0
    while (at := start + n / rate_hz) < start + seconds:
        for text in sentences:
            offset = 0.0
            for offset, part in pieces(text, baud, piece_ms):
                time.sleep(max(0.0, at + offset - time.monotonic()))
                pty.write(part.decode())
            at += offset
        ends.append(time.monotonic())
        n += 1


def latest_steps(stats, names) -> dict[str, int]:
    """Each plug-in's steps from its latest counters (sent once a second)."""
    steps: dict[str, int] = {}
    deadline = time.monotonic() + 3.0
    while set(names) - set(steps) and time.monotonic() < deadline:
        for row in stats.take(0.5):
            steps[row.name.decode()] = row.steps
    return steps


def report(vehicle: Vehicle, ptys: dict[str, Pty], seconds: float) -> None:
    stats = vehicle.bus.queue_reader("system/plugin_stats")
    readers = {n: vehicle.bus.queue_reader(d[4]) for n, d in DEVICES.items()}
    for name, (_, _, _, _, _, sentences) in DEVICES.items():  # heard, counters flowing
        for _ in range(20):
            ptys[name].write("".join(sentences))
            if readers[name].take(0.2):
                break
    list(stats.drain())
    before = latest_steps(stats, DEVICES)
    pids = {n: vehicle.row(n).pid for n in DEVICES}
    cpu_before, t_before = {n: cpu_seconds(pid) for n, pid in pids.items()}, time.monotonic()
    for reader in readers.values():
        list(reader.drain())
    ends: dict[str, list[float]] = {n: [] for n in DEVICES}
    arrivals: dict[str, list[float]] = {n: [] for n in DEVICES}
    writers = [
        threading.Thread(target=feed, args=(ptys[n], d, seconds, ends[n]), daemon=True)
        for n, d in DEVICES.items()
    ]
    for w in writers:
        w.start()
    stop = time.monotonic() + seconds + 1.0
    while time.monotonic() < stop:
        for name, reader in readers.items():
            got = list(reader.drain())
            arrivals[name] += [time.monotonic()] * len(got)
        time.sleep(0.0005)
    cpu = {n: cpu_seconds(pid) - cpu_before[n] for n, pid in pids.items()}
    wall = time.monotonic() - t_before
    time.sleep(1.2)  # the counters of the last second
    list(stats.drain())
    after = latest_steps(stats, DEVICES)
    print(f"{'device':8} {'baud':>7} {'samples':>8} {'published':>9} {'steps/sample':>12}"
          f" {'CPU %':>6}  last piece -> bus p50 / p99 / max (ms)")  # fmt: skip
    for name, (_, baud, _, piece_ms, _, _) in DEVICES.items():
        per = (after[name] - before[name]) / max(1, len(ends[name]))
        delays = sorted(1e3 * (a - e) for a, e in zip(arrivals[name], ends[name], strict=False))
        p50 = statistics.median(delays) if delays else float("nan")
        p99 = delays[min(len(delays) - 1, int(0.99 * len(delays)))] if delays else float("nan")
        worst = delays[-1] if delays else float("nan")
        print(f"{name:8} {baud:>7} {len(ends[name]):>8} {len(arrivals[name]):>9} {per:>12.1f}"
              f" {100 * cpu[name] / wall:>6.2f}  {p50:.2f} / {p99:.2f} / {worst:.2f}"
              f"  (pieces of {piece_ms} ms)")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=10.0)
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="serial_pieces"))
    ptys = {name: Pty(tmp / f"tty_{name}") for name in DEVICES}
    specs = (plugin(n, d[0], device=ptys[n].link, baud=d[1]) for n, d in DEVICES.items())
    vehicle = Vehicle(vehicle_config("pieces", *specs), tmp, None).start()
    try:
        for name in DEVICES:
            vehicle.wait_running(name, 60)
        report(vehicle, ptys, args.seconds)
    finally:
        vehicle.close()


if __name__ == "__main__":
    main()
