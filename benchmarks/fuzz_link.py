"""A hostile ground station against a running ``companion sim``, on UDP and on a serial pty.

    uv run python benchmarks/fuzz_link.py [--frames 1000000] [--seed 1]

The vehicle flies in real time in JSBSim with a stored mission. One stream of hostile
frames (random bytes, one-byte-mutated and truncated frames, well-formed frames whose
values their rules refuse; tests/support/hostile.py) goes to a UDP endpoint as fast as
the vehicle answers (at most WINDOW commands unanswered), another to a 57600-baud serial
endpoint at the wire's pace, until --frames have gone out on UDP. Printed: frames sent
and commands answered per endpoint, restarts of every plug-in (must be 0), ATTITUDE rate
before, during and after (must hold; the socket is drained before each window, so
datagrams queued while nothing read are not counted), and the stored mission's and the
parameters' checksums, each before and after (must match).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import select
import socket
import subprocess
import sys
import tempfile
import termios
import threading
import time
from collections import Counter
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from companion.testing.processes import free_udp_port  # noqa: E402
from mavlink_dialect import companion as m  # noqa: E402
from tests.support.hostile import HostileStream  # noqa: E402

WINDOW = 16  # commands in flight on UDP before the sender waits for answers
SERIAL_BYTES_PER_S = 57600 / 10
STALL_S = 1.0


def raw_pty() -> tuple[int, str]:
    master, slave = os.openpty()
    attrs = termios.tcgetattr(slave)
    attrs[3] &= ~(termios.ECHO | termios.ICANON)
    termios.tcsetattr(slave, termios.TCSANOW, attrs)
    return master, os.ttyname(slave)


def state_digest(state: Path, missions: bool) -> str:
    """The stored missions' files (``missions``) or every other stored file (parameters)."""
    h = hashlib.sha256()
    for p in sorted(q for q in state.rglob("*") if q.is_file() and q.suffix != ".tmp"):
        if ("mission" in str(p.relative_to(state))) == missions:
            h.update(p.name.encode() + p.read_bytes())
    return h.hexdigest()[:16]


def digests(state: Path) -> tuple[str, str]:
    """(missions, parameters)."""
    return state_digest(state, True), state_digest(state, False)


def restarts(namespace: str) -> dict[str, int]:
    done = subprocess.run(
        [sys.executable, "-m", "companion", "status", "--json", "-n", namespace],
        capture_output=True, text=True, cwd=REPO, timeout=60,
    )  # fmt: skip
    rows = json.loads(done.stdout)["plugins"]
    return {row["name"]: row["restarts"] for row in rows}


class UdpStation:
    """The ground station on UDP: sends, and counts what comes back."""

    def __init__(self, port: int) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.addr = ("127.0.0.1", port)
        self.mav = m.MAVLink(None, srcSystem=255, srcComponent=190)
        self.parser = m.MAVLink(None)
        self.parser.robust_parsing = True
        self.seen: Counter[str] = Counter()
        self.acks = 0

    def send(self, data: bytes) -> None:
        self.sock.sendto(data, self.addr)

    def read(self, timeout_s: float = 0.0) -> None:
        while select.select([self.sock], [], [], timeout_s)[0]:
            timeout_s = 0.0
            for msg in self.parser.parse_buffer(self.sock.recv(65536)) or []:
                self.seen[msg.get_type()] += 1
                self.acks += msg.get_type() == "COMMAND_ACK"

    def drain(self) -> None:
        """Read what queued while nobody read, so a rate counts only its own window."""
        self.read()

    def attitude_rate(self, seconds: float) -> float:
        self.drain()
        before, end = self.seen["ATTITUDE"], time.monotonic() + seconds
        while time.monotonic() < end:
            self.read(0.05)
        return (self.seen["ATTITUDE"] - before) / seconds

    def connect(self, timeout_s: float = 90.0) -> None:
        deadline = time.monotonic() + timeout_s
        while self.seen["HEARTBEAT"] == 0:
            if time.monotonic() > deadline:
                raise SystemExit("no HEARTBEAT from the vehicle on UDP")
            self.send(self.mav.heartbeat_encode(6, 8, 192, 0, 4).pack(self.mav))
            self.read(0.5)


class SerialFuzzer(threading.Thread):
    """Hostile frames on the serial endpoint at the wire's pace; counts what comes back."""

    def __init__(self, master: int, seed: int) -> None:
        super().__init__(daemon=True)
        self.master, self.stream = master, HostileStream(seed=seed)
        self.stop = threading.Event()
        self.frames = self.commands = self.acks = self.attitudes = 0
        self.parser = m.MAVLink(None)
        self.parser.robust_parsing = True

    def run(self) -> None:
        credit, last = 0.0, time.monotonic()
        pending = b""
        while not self.stop.is_set():
            now = time.monotonic()
            credit, last = min(credit + (now - last) * SERIAL_BYTES_PER_S, 2048), now
            if not pending:
                frame = self.stream.frame()
                pending = frame.data
                self.frames += 1
                self.commands += frame.command is not None
            if credit >= len(pending):
                os.write(self.master, pending)
                credit -= len(pending)
                pending = b""
            while select.select([self.master], [], [], 0.005)[0]:
                for msg in self.parser.parse_buffer(os.read(self.master, 4096)) or []:
                    self.acks += msg.get_type() == "COMMAND_ACK"
                    self.attitudes += msg.get_type() == "ATTITUDE"


def fuzz_udp(station: UdpStation, frames: int, seed: int) -> tuple[int, float]:
    """Send ``frames`` hostile frames; returns (commands sent, seconds taken).

    At most WINDOW commands wait for their answer; one not answered within STALL_S is
    written off (it shows as unanswered in the report) so the stream goes on.
    """
    stream, commands, t0 = HostileStream(seed=seed), 0, time.monotonic()
    written_off, last_progress, last_acks = 0, t0, 0
    for i in range(frames):
        frame = stream.frame()
        station.send(frame.data)
        commands += frame.command is not None
        while commands - station.acks - written_off >= WINDOW:
            station.read(0.01)
            now = time.monotonic()
            if station.acks != last_acks:
                last_acks, last_progress = station.acks, now
            elif now - last_progress > STALL_S:
                written_off, last_progress = commands - station.acks, now
        if i % 256 == 0:
            station.read()
        if i % 100_000 == 0 and i:
            print(f"  {i} frames on UDP, {time.monotonic() - t0:.0f} s", flush=True)
    deadline = time.monotonic() + 15
    while station.acks < commands and time.monotonic() < deadline:
        station.read(0.1)
    return commands, time.monotonic() - t0


def start_sim(tmp: Path, namespace: str, udp_port: int, tty: str) -> subprocess.Popen[bytes]:
    cmd = [
        sys.executable, "-m", "companion", "sim", "--plan", "qgc_plans/square.plan",
        "--airborne", "--duration", "100000", "--state-dir", str(tmp / "state"),
        "--namespace", namespace, "--log-level", "ERROR",
        "--link", f"udpin://127.0.0.1:{udp_port}", "--link", f"serial://{tty}:57600",
    ]  # fmt: skip
    return subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.DEVNULL)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--frames", type=int, default=1_000_000, help="hostile frames on UDP")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="fuzz_link"))
    namespace, udp_port = f"fz{os.getpid()}", free_udp_port()
    master, tty = raw_pty()
    sim = start_sim(tmp, namespace, udp_port, tty)
    try:
        station = UdpStation(udp_port)
        station.connect()
        station.send(station.mav.param_set_encode(1, 1, b"SR_GPS", 3.0, 9).pack(station.mav))
        time.sleep(3.0)  # the parameter file and the mission are on disk
        digest_before, rate_before = digests(tmp / "state"), station.attitude_rate(5.0)
        serial = SerialFuzzer(master, args.seed + 1)
        serial.start()
        station.drain()
        attitudes_before = station.seen["ATTITUDE"]
        commands, seconds = fuzz_udp(station, args.frames, args.seed)
        rate_during = (station.seen["ATTITUDE"] - attitudes_before) / seconds
        serial.stop.set()
        serial.join()
        time.sleep(2.0)  # the last serial answers
        rate_after = station.attitude_rate(5.0)
        report(args.frames, commands, station, serial, seconds, namespace)
        print(f"ATTITUDE on UDP: {rate_before:.1f} Hz before, {rate_during:.1f} during, "
              f"{rate_after:.1f} after")  # fmt: skip
        after = digests(tmp / "state")
        for name, was, now in zip(("mission", "parameters"), digest_before, after, strict=True):
            same = "match" if now == was else "DIFFER"
            print(f"{name} checksum: {was} before, {now} after: {same}")
    finally:
        sim.terminate()
        sim.wait(timeout=30)
        os.close(master)


def report(frames, commands, station, serial, seconds, namespace) -> None:
    print(f"UDP: {frames} frames in {seconds:.0f} s ({frames / seconds:.0f}/s), "
          f"{commands} commands, {station.acks} answered")  # fmt: skip
    print(f"serial 57600: {serial.frames} frames, {serial.commands} commands, "
          f"{serial.acks} answered, {serial.attitudes} ATTITUDE heard")  # fmt: skip
    counts = restarts(namespace)
    print(f"plug-in restarts: {sum(counts.values())} ({counts})")


if __name__ == "__main__":
    main()
