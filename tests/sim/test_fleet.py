"""``companion sim --count 2``: two whole vehicles, one ground-station port, an API port each.

A ground station on the shared port hears both aircraft and, as QGroundControl's UDP link
does, sends every command to every address it heard: the command addressed to sysid 2
reaches vehicle 1 as well, and only vehicle 2 may act on it.
"""

from __future__ import annotations

import contextlib
import math
import os
import select
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable

import numpy as np
import psutil
import pytest

os.environ.setdefault("MAVLINK20", "1")

from bridges.jsbsim.fdm import Home
from companion.bus.namespace import cleanup_namespace
from companion.geodesy import LocalFrame
from companion.navigation.estimate_csv import read_estimate as read_truth
from mavlink_dialect import companion as d
from tests.protocol.mav_client import free_udp_port
from tests.support.vehicle import REPO, assert_clean, companion_env, unique_namespace

PLAN = REPO / "qgc_plans" / "loiter.plan"
SPACING_M = 50.0
ARMED = d.MAV_MODE_FLAG_SAFETY_ARMED
ACCEPTED = d.MAV_RESULT_ACCEPTED


class Station:
    """UDP ports bound as ground tools bind them; every frame kept with where it came from."""

    def __init__(self, ports: list[int]) -> None:
        self.socks = {}
        for port in ports:
            sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            sock.bind(("127.0.0.1", port))
            self.socks[port] = sock
        self.mav = d.MAVLink(None, srcSystem=255, srcComponent=190)
        self.parsers: dict[tuple, d.MAVLink] = {}
        self.peers: dict[tuple[int, int], tuple[str, int]] = {}  # (port, sysid) → address
        self.seen: list[tuple[int, object]] = []  # (local port, message)
        self.next_beat = 0.0

    def pump(self, seconds: float) -> None:
        """Receive for a while, beating once a second on every port to every peer."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if time.monotonic() >= self.next_beat:
                self.next_beat = time.monotonic() + 1.0
                for port in self.socks:
                    self.send(port, self.mav.heartbeat_encode(d.MAV_TYPE_GCS, 8, 192, 0, 4))
            ready, _, _ = select.select(list(self.socks.values()), [], [], 0.05)
            for sock in ready:
                self._read(sock)

    def _read(self, sock: socket.socket) -> None:
        port = sock.getsockname()[1]
        data, addr = sock.recvfrom(65535)
        parser = self.parsers.setdefault((port, addr), d.MAVLink(None))
        parser.robust_parsing = True
        for msg in parser.parse_buffer(data) or []:
            if msg.get_type() == "BAD_DATA":
                continue
            self.peers[(port, msg.get_srcSystem())] = addr
            self.seen.append((port, msg))

    def send(self, port: int, msg: object, sysids: tuple[int, ...] | None = None) -> None:
        """Send to the given vehicles' addresses on that port (all heard there if None)."""
        raw = msg.pack(self.mav)
        for (p, sysid), addr in list(self.peers.items()):
            if p == port and (sysids is None or sysid in sysids):
                self.socks[port].sendto(raw, addr)

    def command(self, port: int, target: int, command: int, *params: float, to=None) -> None:
        values = [*params, 0, 0, 0, 0, 0, 0, 0][:7]
        self.send(port, self.mav.command_long_encode(target, 1, command, 0, *values), to)

    def messages(self, port: int, kind: str, sysid: int | None = None) -> list:
        return [
            m for p, m in self.seen
            if p == port and m.get_type() == kind and sysid in (None, m.get_srcSystem())
        ]  # fmt: skip

    def until(self, predicate: Callable[[], object], seconds: float, what: str) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.pump(0.2)
            if predicate():
                return
        raise AssertionError(f"not {what} within {seconds} s")

    def acked(self, port: int, sysid: int, command: int) -> bool:
        acks = self.messages(port, "COMMAND_ACK", sysid)
        return any(a.command == command and a.result == ACCEPTED for a in acks)

    def close(self) -> None:
        for sock in self.socks.values():
            sock.close()


def consecutive_free_ports() -> int:
    """A port P with P and P + 1 both free (the fleet's API ports)."""
    for _ in range(50):
        base = free_udp_port()
        with contextlib.suppress(OSError), socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.bind(("127.0.0.1", base + 1))
            return base
    raise AssertionError("no two consecutive free UDP ports")


def east_north(lat: float, lon: float) -> tuple[float, float]:
    north, east = LocalFrame(Home().lat_deg, Home().lon_deg).ne(lat, lon)
    return east, north


def family(pid: int) -> list[psutil.Process]:
    with contextlib.suppress(psutil.NoSuchProcess):
        return [psutil.Process(pid), *psutil.Process(pid).children(recursive=True)]
    return []


def gone(proc: psutil.Process) -> bool:
    try:
        return proc.status() == psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return True


def start_fleet(tmp_path, namespace: str, gcs: int, api: int) -> subprocess.Popen[str]:
    cmd = [
        sys.executable, "-m", "companion", "sim", "--count", "2", "--speed", "1",
        "--namespace", namespace, "--state-dir", str(tmp_path / "state"),
        "--truth", str(tmp_path / "truth.csv"), "--link", f"udpout://127.0.0.1:{gcs}",
        "--api-port-base", str(api), "--plan", str(PLAN), "--duration", "600",
    ]  # fmt: skip
    return subprocess.Popen(
        cmd, env=companion_env(namespace), cwd=REPO, text=True,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
    )  # fmt: skip


def fly_vehicle_two(station: Station, gcs: int) -> None:
    """Both heard with a position; then arm and start the mission of sysid 2 only."""
    station.until(
        lambda: station.messages(gcs, "HOME_POSITION", 2)
        and all(station.messages(gcs, "GLOBAL_POSITION_INT", i) for i in (1, 2)),
        90, "both vehicles heard with a position and vehicle 2 with a home",
    )  # fmt: skip
    station.command(gcs, 2, d.MAV_CMD_COMPONENT_ARM_DISARM, 1)  # to both addresses, as QGC
    station.until(lambda: station.acked(gcs, 2, d.MAV_CMD_COMPONENT_ARM_DISARM), 10, "armed")
    station.command(gcs, 2, d.MAV_CMD_MISSION_START, 0, 0)
    station.until(lambda: station.acked(gcs, 2, d.MAV_CMD_MISSION_START), 10, "started")


def climbing(station: Station, gcs: int) -> bool:
    return any(m.relative_alt > 10_000 for m in station.messages(gcs, "GLOBAL_POSITION_INT", 2))


def check_api_ports(station: Station, api: int) -> None:
    """Vehicle i alone on API port api + i - 1, and it answers there."""
    for i in (1, 2):
        port = api + i - 1
        station.command(port, i, d.MAV_CMD_REQUEST_MESSAGE, d.MAVLINK_MSG_ID_AUTOPILOT_VERSION)
        station.until(lambda: station.acked(port, i, d.MAV_CMD_REQUEST_MESSAGE), 10, f"API {i}")  # noqa: B023
        # The vehicle forwards what it hears from ground stations (ours among them, sysid
        # 255), as mavlink-router does; of the aircraft, only vehicle i is on this port.
        heard = {m.get_srcSystem() for m in station.messages(port, "HEARTBEAT")}
        assert heard - {255} == {i}, (port, heard)


def stop_fleet(proc: subprocess.Popen[str], namespace: str) -> str:
    """Ctrl-C as at a terminal; everything must end, and nothing stay in /dev/shm."""
    everyone = family(proc.pid)
    assert len(everyone) >= 2 * 8, [p.name() for p in everyone]  # two vehicles' processes
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=40)
    assert proc.returncode == 0, out
    assert all(gone(p) for p in everyone), [p.pid for p in everyone if not gone(p)]
    for ns in (f"{namespace}_v1", f"{namespace}_v2", namespace):
        assert_clean(ns)
    return out


def check_truth(tmp_path, positions: dict[int, list]) -> None:
    """Each vehicle where it should be, and its MAVLink position its own true one."""
    truth = {i: read_truth(tmp_path / f"truth_v{i}.csv") for i in (1, 2)}
    start = {i: east_north(truth[i]["lat"][0], truth[i]["lon"][0]) for i in (1, 2)}
    assert start[1] == pytest.approx((0.0, 0.0), abs=0.5)
    assert start[2] == pytest.approx((SPACING_M, 0.0), abs=0.5)
    alt1, alt2 = np.array(truth[1]["alt"]), np.array(truth[2]["alt"])
    assert np.ptp(alt1) < 2.0 and np.hypot(truth[1]["vn"], truth[1]["ve"]).max() < 3.0
    assert alt2.max() > alt2[0] + 10.0
    for i in (1, 2):
        t = np.array(truth[i]["t"])
        for msg in positions[i]:
            k = min(int(np.searchsorted(t, msg.time_boot_ms / 1000.0)), len(t) - 1)
            e_t, n_t = east_north(truth[i]["lat"][k], truth[i]["lon"][k])
            e_m, n_m = east_north(msg.lat / 1e7, msg.lon / 1e7)
            assert math.hypot(e_t - e_m, n_t - n_m) < 15.0, (i, msg.time_boot_ms)


@pytest.mark.timeout(180)
def test_two_vehicles_share_the_ground_station_and_fly_alone(tmp_path):
    gcs, api = free_udp_port(), consecutive_free_ports()
    station = Station([gcs, api, api + 1])
    namespace = unique_namespace("fleet")
    proc = start_fleet(tmp_path, namespace, gcs, api)
    try:
        fly_vehicle_two(station, gcs)
        first = {i: station.messages(gcs, "GLOBAL_POSITION_INT", i)[-1] for i in (1, 2)}
        (e1, n1), (e2, n2) = (east_north(m.lat / 1e7, m.lon / 1e7) for m in first.values())
        assert e2 - e1 == pytest.approx(SPACING_M, abs=10.0) and abs(n2 - n1) < 10.0
        check_api_ports(station, api)
        station.until(lambda: climbing(station, gcs), 90, "vehicle 2 climbing")
        beats = {i: station.messages(gcs, "HEARTBEAT", i) for i in (1, 2)}
        assert beats[2][-1].base_mode & ARMED
        assert not any(b.base_mode & ARMED for b in beats[1])
        assert all(
            abs(m.relative_alt) < 3000 for m in station.messages(gcs, "GLOBAL_POSITION_INT", 1)
        )
        assert not any(
            a.command in (d.MAV_CMD_COMPONENT_ARM_DISARM, d.MAV_CMD_MISSION_START)
            for a in station.messages(gcs, "COMMAND_ACK", 1)
        ), "vehicle 1 acted on a command addressed to vehicle 2"
        stop_fleet(proc, namespace)
    finally:
        if proc.poll() is None:
            for p in reversed(family(proc.pid)):
                with contextlib.suppress(psutil.NoSuchProcess):
                    p.kill()
            proc.communicate()
        for ns in (f"{namespace}_v1", f"{namespace}_v2"):
            cleanup_namespace(ns)
        station.close()
    positions = {i: station.messages(gcs, "GLOBAL_POSITION_INT", i) for i in (1, 2)}
    check_truth(tmp_path, positions)
