"""Log download throughput, as QGroundControl downloads: over loopback UDP, and over a
57600-baud radio (a pty read no faster than the radio would deliver), with the telemetry
rates seen during the download beside those seen before it.

Usage: uv run python benchmarks/log_download.py [--udp-kb 2000] [--radio-kb 40] [--log F.ulg]

The log is ``--log`` (a real flight log) or random bytes of the given size, put in the
vehicle's log directory; the vehicle is a link, a known navigation solution and an IMU.
"""

from __future__ import annotations

import argparse
import fcntl
import os
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import termios
import time
from collections import Counter
from pathlib import Path
from typing import Any

os.environ.setdefault("MAVLINK20", "1")
REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
from mavlink_dialect import companion as m  # noqa: E402
from tests.protocol.log_client import QgcDownload  # noqa: E402
from tests.protocol.mav_client import GroundStation, free_udp_port  # noqa: E402
from tests.support.configs import TICKER, client_vehicle, plugin  # noqa: E402

RADIO_BYTES_S = 57600 / 10


def start_vehicle(endpoint: str, state: Path, log: Path | None, size: int) -> Any:
    (state / "logs").mkdir(parents=True)
    target = state / "logs" / "0001_armed.ulg"
    if log is not None:
        shutil.copyfile(log, target)
    else:
        target.write_bytes(os.urandom(size))
    config = state.parent / f"{state.name}.toml"
    config.write_text(client_vehicle(endpoint, state, extra=(plugin("imu", TICKER),)))
    env = {**os.environ, "COMPANION_BUS": f"ld{os.getpid()}{state.name}", "PYTHONPATH": str(REPO)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "companion", "run", "-c", str(config), "--log-level", "WARNING"],
        env=env,
        cwd=REPO,
    )
    return proc, target


def stop(proc: Any) -> None:
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=10)


class Counting:
    """Wraps a connection's recv_match: every message is counted on the way."""

    def __init__(self, conn: Any) -> None:
        self.conn, self.counts = conn, Counter()

    def recv_match(self, type: Any = None, blocking: bool = True, timeout: float = 0.2) -> Any:
        deadline = time.monotonic() + timeout
        while True:
            msg = self.conn.recv_match(blocking=True, timeout=max(0.0, deadline - time.monotonic()))
            if msg is None:
                return None
            self.counts[msg.get_type()] += 1
            if type is None or msg.get_type() == type:
                return msg


def report(name: str, size: int, seconds: float, dl: QgcDownload, before: Counter, during: Counter,
           before_s: float) -> None:  # fmt: skip
    print(f"{name}: {size} bytes in {seconds:.1f} s = {size / seconds / 1000:.1f} kB/s, "
          f"{dl.requests} requests")  # fmt: skip
    for kind in ("HEARTBEAT", "ATTITUDE", "GLOBAL_POSITION_INT"):
        print(f"  {kind:20} {before[kind] / before_s:5.1f} Hz before, "
              f"{during[kind] / seconds:5.1f} Hz during")  # fmt: skip


def over_udp(tmp: Path, log: Path | None, size: int) -> None:
    port = free_udp_port()
    proc, target = start_vehicle(f"udpin://127.0.0.1:{port}", tmp / "udp", log, size)
    gcs = GroundStation(port)
    counting = Counting(gcs.conn)
    try:
        gcs.connect()
        t0 = time.monotonic()
        while time.monotonic() - t0 < 3.0:
            gcs.heartbeat()
            counting.recv_match(type="NONE", timeout=0.5)
        before, counting.counts = counting.counts, Counter()
        gcs.conn = counting  # type: ignore[assignment]
        real = target.stat().st_size
        dl = QgcDownload(gcs, 0, real)
        t0 = time.monotonic()
        data = dl.run()
        seconds = time.monotonic() - t0
        assert data == target.read_bytes(), "the download differs from the file"
        report("UDP", real, seconds, dl, before, counting.counts, 3.0)
    finally:
        try:
            counting.conn.close()
        finally:
            stop(proc)


class Radio:
    """The ground end of a 57600-baud radio on a pty: reads no faster than the radio."""

    def __init__(self, master: int) -> None:
        self.master = master
        self.parser = m.MAVLink(None)
        self.parser.robust_parsing = True
        self.mav = m.MAVLink(self, srcSystem=255, srcComponent=190)
        self.credit, self.last = 0.0, time.monotonic()
        self.pending: list[Any] = []
        self.counts: Counter[str] = Counter()

    def write(self, data: bytes) -> None:
        os.write(self.master, data)

    def recv_match(self, type: Any = None, blocking: bool = True, timeout: float = 0.2) -> Any:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            while self.pending:
                msg = self.pending.pop(0)
                self.counts[msg.get_type()] += 1
                if type is None or msg.get_type() == type:
                    return msg
            now = time.monotonic()
            self.credit = min(self.credit + (now - self.last) * RADIO_BYTES_S, 512)
            self.last = now
            raw = fcntl.ioctl(self.master, termios.FIONREAD, b"\0" * 4)
            take = int(min(self.credit, int.from_bytes(raw, "little")))
            if take > 0:
                self.credit -= take
                self.pending += self.parser.parse_buffer(os.read(self.master, take)) or []
            else:
                select.select([], [], [], 0.005)
        return None


def over_radio(tmp: Path, size: int) -> None:
    master, slave = os.openpty()
    attrs = termios.tcgetattr(slave)
    attrs[3] &= ~(termios.ECHO | termios.ICANON)
    termios.tcsetattr(slave, termios.TCSANOW, attrs)
    proc, target = start_vehicle(f"serial://{os.ttyname(slave)}:57600", tmp / "radio", None, size)
    radio = Radio(master)
    gcs = GroundStation.__new__(GroundStation)
    gcs.conn, gcs.mav = radio, radio.mav
    try:
        if radio.recv_match(type="HEARTBEAT", timeout=60.0) is None:
            raise SystemExit("no heartbeat on the pty")
        radio.counts = Counter()
        radio.recv_match(type="NONE", timeout=5.0)
        before, radio.counts = radio.counts, Counter()
        dl = QgcDownload(gcs, 0, size)
        t0 = time.monotonic()
        data = dl.run(timeout_s=600.0)
        seconds = time.monotonic() - t0
        assert data == target.read_bytes(), "the download differs from the file"
        report("57600-baud pty", size, seconds, dl, before, radio.counts, 5.0)
    finally:
        stop(proc)
        os.close(master)
        os.close(slave)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--udp-kb", type=int, default=2000, help="log size over UDP")
    parser.add_argument("--radio-kb", type=int, default=40, help="log size over the radio")
    parser.add_argument("--log", type=Path, help="a real log to download over UDP")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        over_udp(Path(tmp), args.log, args.udp_kb * 1000)
        over_radio(Path(tmp), args.radio_kb * 1000)


if __name__ == "__main__":
    main()
