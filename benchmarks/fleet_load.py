"""What each vehicle of ``companion sim --count N`` costs: processes, CPU, memory, shared memory.

Usage: uv run python benchmarks/fleet_load.py [--count 2] [--seconds 60] [--speed 1]

Starts the fleet in real time with the loiter plan, arms every vehicle and starts its
mission from a ground station on the shared port (so each one flies, with its flight
group running), waits until all are airborne, then measures each vehicle's process tree
over ``--seconds`` of wall time: CPU (percent of one core), resident memory (RSS, which
counts shared library pages in every process) and unique memory (USS, what the vehicle
alone holds), and its files in /dev/shm.
"""

from __future__ import annotations

import argparse
import os
import select
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil

os.environ.setdefault("MAVLINK20", "1")

from mavlink_dialect import companion as d

REPO = Path(__file__).resolve().parents[1]
PLAN = REPO / "qgc_plans" / "loiter.plan"
MB = 1024 * 1024


class Station:
    """The shared ground-station port: hears every vehicle, commands each by its sysid."""

    def __init__(self) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.mav = d.MAVLink(None, srcSystem=255, srcComponent=190)
        self.parsers: dict[tuple, d.MAVLink] = {}
        self.addr: dict[int, tuple] = {}
        self.home: set[int] = set()
        self.alt_m: dict[int, float] = {}
        self.t_s: dict[int, float] = {}  # the vehicle's time (simulation time)
        self.next_beat = 0.0

    def pump(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if time.monotonic() >= self.next_beat:
                self.next_beat = time.monotonic() + 1.0
                for sysid in self.addr:
                    self.send(sysid, self.mav.heartbeat_encode(d.MAV_TYPE_GCS, 8, 192, 0, 4))
            if select.select([self.sock], [], [], 0.05)[0]:
                data, addr = self.sock.recvfrom(65535)
                parser = self.parsers.setdefault(addr, d.MAVLink(None))
                for msg in parser.parse_buffer(data) or []:
                    self._note(msg, addr)

    def _note(self, msg: object, addr: tuple) -> None:
        sysid, kind = msg.get_srcSystem(), msg.get_type()
        self.addr[sysid] = addr
        if kind == "HOME_POSITION":
            self.home.add(sysid)
        elif kind == "GLOBAL_POSITION_INT":
            self.alt_m[sysid] = msg.relative_alt / 1000.0
            self.t_s[sysid] = msg.time_boot_ms / 1000.0

    def send(self, sysid: int, msg: object) -> None:
        self.sock.sendto(msg.pack(self.mav), self.addr[sysid])

    def command(self, sysid: int, command: int, *params: float) -> None:
        values = [*params, 0, 0, 0, 0, 0, 0, 0][:7]
        self.send(sysid, self.mav.command_long_encode(sysid, 1, command, 0, *values))

    def until(self, predicate, seconds: float, what: str) -> None:
        end = time.monotonic() + seconds
        while not predicate():
            if time.monotonic() > end:
                raise SystemExit(f"not {what} within {seconds} s")
            self.pump(0.2)


def vehicles(root: psutil.Process) -> dict[int, list[psutil.Process]]:
    """Each vehicle's process tree, by sysid (read from its command line)."""
    out = {}
    for child in root.children():
        cmd = child.cmdline()
        sysid = int(cmd[cmd.index("--sysid") + 1])
        out[sysid] = [child, *child.children(recursive=True)]
    return out


def cpu_s(procs: list[psutil.Process]) -> float:
    total = 0.0
    for p in procs:
        try:
            t = p.cpu_times()
            total += t.user + t.system
        except psutil.Error:
            pass
    return total


def memory(procs: list[psutil.Process]) -> tuple[float, float]:
    rss = uss = 0
    for p in procs:
        try:
            info = p.memory_full_info()
            rss, uss = rss + info.rss, uss + info.uss
        except psutil.Error:
            pass
    return rss / MB, uss / MB


def shm_mb(namespace: str) -> tuple[int, float]:
    files = list(Path("/dev/shm").glob(f"cmp_{namespace}_*"))
    return len(files), sum(f.stat().st_size for f in files) / MB


def fly_all(station: Station, count: int) -> None:
    wanted = set(range(1, count + 1))
    station.until(lambda: station.home >= wanted, 180, "every vehicle with a home")
    for sysid in sorted(wanted):
        station.command(sysid, d.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        station.pump(0.5)
        station.command(sysid, d.MAV_CMD_MISSION_START, 0, 0)
    airborne = lambda: all(station.alt_m.get(i, 0.0) > 30.0 for i in wanted)  # noqa: E731
    station.until(airborne, 180, "every vehicle 30 m up")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=2)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--speed", default="1")
    args = parser.parse_args()
    namespace = f"fleetbench{os.getpid()}"
    station = Station()
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [
            sys.executable, "-m", "companion", "sim", "--count", str(args.count),
            "--speed", args.speed, "--plan", str(PLAN), "--namespace", namespace,
            "--state-dir", tmp, "--link", f"udpout://127.0.0.1:{station.port}",
            "--api-port-base", "0", "--log-level", "WARNING",
        ]  # fmt: skip
        proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
        try:
            fly_all(station, args.count)
            measure(psutil.Process(proc.pid), station, args.seconds, namespace)
        finally:
            proc.send_signal(signal.SIGINT)
            proc.wait(60)


def measure(root: psutil.Process, station: Station, seconds: float, namespace: str) -> None:
    trees = vehicles(root)
    before = {i: cpu_s(t) for i, t in trees.items()}
    parent_before = cpu_s([root])
    started, sim_before = time.monotonic(), dict(station.t_s)
    station.pump(seconds)
    wall = time.monotonic() - started
    print(f"{len(trees)} vehicles in real time, measured over {wall:.0f} s, all flying")
    for i, tree in sorted(trees.items()):
        cpu = (cpu_s(tree) - before[i]) / wall * 100
        rss, uss = memory(tree)
        files, shm = shm_mb(f"{namespace}_v{i}")
        factor = (station.t_s[i] - sim_before[i]) / wall
        print(
            f"vehicle {i}: x{factor:4.2f}, {len(tree)} processes, CPU {cpu:5.1f} % of a core,"
            f" RSS {rss:6.0f} MB, USS {uss:5.0f} MB, /dev/shm {files} files {shm:5.1f} MB"
        )
    parent_cpu = (cpu_s([root]) - parent_before) / wall * 100
    print(f"fleet parent: CPU {parent_cpu:4.1f} % of a core, RSS {memory([root])[0]:4.0f} MB")
    print(f"machine: {psutil.cpu_count()} CPUs, {psutil.virtual_memory().total / MB:.0f} MB")


if __name__ == "__main__":
    main()
