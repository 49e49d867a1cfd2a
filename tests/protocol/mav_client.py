"""A pymavlink ground station on loopback UDP, for the protocol tests."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

os.environ.setdefault("MAVLINK20", "1")

from pymavlink import mavutil

from companion.testing.processes import free_udp_port
from mavlink_dialect import companion as d
from mavlink_dialect import companion as dialect
from tests.support.configs import FAKE_NAV, link, plugin, vehicle_config

__all__ = [
    "GroundStation",
    "answer",
    "connected_station",
    "free_udp_port",
    "two_stations",
    "upload_mission",
]


class GroundStation:
    """QGroundControl's identity (sysid 255, compid 190) speaking to the vehicle's udpin."""

    def __init__(self, port: int, sysid: int = 255, compid: int = 190) -> None:
        self.conn = mavutil.mavlink_connection(
            f"udpout:127.0.0.1:{port}", source_system=sysid, source_component=compid
        )
        # Speak the vehicle's own dialect, so its messages (PROTOCOL_VERSION, ...) decode.
        self.conn.mav = dialect.MAVLink(self.conn, srcSystem=sysid, srcComponent=compid)
        self.conn.mav.robust_parsing = True
        self.mav = self.conn.mav

    def heartbeat(self) -> None:
        self.mav.heartbeat_send(6, 8, 192, 0, 4)  # GCS, INVALID autopilot, as QGC sends

    def connect(self, timeout_s: float = 60.0) -> Any:
        """Send heartbeats until the vehicle's heartbeat comes back."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            self.heartbeat()
            msg = self.conn.recv_match(type="HEARTBEAT", blocking=True, timeout=0.5)
            if msg is not None and msg.get_srcSystem() == 1:
                return msg
        raise AssertionError("no HEARTBEAT from the vehicle")

    # A busy machine can hold the vehicle's answer back for seconds: the waits are generous,
    # and a test that passes never waits them out.
    def recv(self, type_: str | list[str], timeout_s: float = 15.0, **match: Any) -> Any:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            msg = self.conn.recv_match(type=type_, blocking=True, timeout=0.2)
            if msg is None:
                continue
            if all(getattr(msg, k) == v for k, v in match.items()):
                return msg
        raise AssertionError(f"no {type_} {match} within {timeout_s} s")

    def command(self, command: int, *params: float, confirmation: int = 0, target=(1, 1)) -> None:
        values = [*params, 0, 0, 0, 0, 0, 0, 0][:7]
        self.mav.command_long_send(target[0], target[1], command, confirmation, *values)

    def ack(self, command: int, timeout_s: float = 15.0) -> Any:
        return self.recv("COMMAND_ACK", timeout_s, command=command)

    def close(self) -> None:
        self.conn.close()


def answer(
    gcs: GroundStation, command: int, *params: float, target=(1, 1), timeout_s: float = 15.0
) -> tuple[Any, str]:
    """Send a command; its COMMAND_ACK and the text of the STATUSTEXTs that came with it,
    chunks joined (a refusal's reason goes out just before the ack, as ArduPilot's)."""
    gcs.command(command, *params, target=target)
    texts: list[str] = []
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        msg = gcs.conn.recv_match(type=["COMMAND_ACK", "STATUSTEXT"], blocking=True, timeout=0.2)
        if msg is None:
            continue
        if msg.get_type() == "STATUSTEXT":
            texts.append(msg.text)
        elif msg.command == command:
            return msg, "".join(texts)
    raise AssertionError(f"no COMMAND_ACK for {command} within {timeout_s} s")


def upload_mission(gcs: GroundStation) -> None:
    """Upload a two-item mission (take-off, one waypoint) as QGroundControl does."""
    mav = gcs.mav
    items = [(d.MAV_CMD_NAV_TAKEOFF, 0.0), (d.MAV_CMD_NAV_WAYPOINT, 0.002)]
    mav.mission_count_send(1, 1, len(items), d.MAV_MISSION_TYPE_MISSION)
    for _ in items:
        req = gcs.recv(["MISSION_REQUEST_INT", "MISSION_REQUEST"], 10)
        cmd, dlat = items[req.seq]
        mav.mission_item_int_send(
            1, 1, req.seq, d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, cmd, 0, 1, 0, 0, 0, 0,
            round((-37.9105 + dlat) * 1e7), round(145.134 * 1e7), 50, d.MAV_MISSION_TYPE_MISSION,
        )  # fmt: skip
    assert gcs.recv("MISSION_ACK", 10).type == d.MAV_MISSION_ACCEPTED


def connected_station(
    vehicle_factory: Any, config: Callable[[str], Path]
) -> Iterator[GroundStation]:
    """For a fixture to yield from: a vehicle started from ``config(udpin URL)`` and a
    ground station connected to it, closed after the test."""
    port = free_udp_port()
    vehicle_factory(config(f"udpin://127.0.0.1:{port}"))
    station = GroundStation(port)
    station.connect()
    yield station
    station.close()


def two_stations(
    vehicle_factory: Any, tmp_path: Any, name: str
) -> tuple[GroundStation, GroundStation]:
    """A vehicle (sysid 1) on two udpin endpoints, and a ground station connected on each:
    QGroundControl's identity on the first, another station's (254, 1: MAVProxy, a script)
    on the second."""
    ports = free_udp_port(), free_udp_port()
    endpoints = [f"udpin://127.0.0.1:{port}" for port in ports]
    config = vehicle_config(
        name, link(*endpoints), plugin("nav", FAKE_NAV), sysid=1, state_dir=tmp_path
    )
    vehicle_factory(config)
    qgc, other = GroundStation(ports[0]), GroundStation(ports[1], sysid=254, compid=1)
    qgc.connect()
    other.connect()
    return qgc, other
