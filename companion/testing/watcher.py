"""The fixture's own MAVLink connection to the vehicle, with pymavlink: what the helpers
(wait until ready, upload a plan, arm and start, run until ...) use.

It is invisible to the test's scripts: it sends no HEARTBEAT and nothing broadcast, only
messages addressed to the vehicle, which the vehicle does not forward to its other
endpoints. A heartbeat (even an onboard controller's) would be forwarded, as
mavlink-router does: a script's MAVSDK counted a second system (253), and pymavlink's
``wait_heartbeat`` could return the helper's. Its keep-alive is a TIMESYNC request to the
vehicle (the vehicle's udpin endpoint learns where to answer from it), and the vehicle's
ground-station failsafe, fed by ground-station heartbeats only, hears nothing from it: a
script's own link loss is the vehicle's, whatever the helpers do meanwhile.
"""

from __future__ import annotations

import os
import socket
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

os.environ.setdefault("MAVLINK20", "1")

from pymavlink import mavutil

from companion.control.mission.plan import load_plan
from companion.control.modes import from_generic, from_px4
from companion.messages import FlightMode
from mavlink_dialect import companion as d

SYSID, COMPID = 253, d.MAV_COMP_ID_ONBOARD_COMPUTER
PREARM = d.MAV_SYS_STATUS_PREARM_CHECK
# A lockstep simulation sends its telemetry several times faster than real time: the
# default receive buffer (208 KiB, some 270 datagrams) holds a fraction of a second of it,
# and a test process not scheduled for longer on a busy machine lost messages (the kernel
# caps this at net.core.rmem_max, 4 MiB here).
RECEIVE_BUFFER = 4 << 20


def widen_receive_buffer(conn: Any) -> None:
    """Let a pymavlink UDP connection's socket hold seconds of telemetry, not a fraction."""
    sock = getattr(conn, "port", None)
    if isinstance(sock, socket.socket):
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, RECEIVE_BUFFER)


class VehicleError(AssertionError):
    """The vehicle did not do what a helper waited for (with what it said meanwhile)."""


class Watcher:
    """A pymavlink connection to one of the vehicle's udpin endpoints."""

    def __init__(self, port: int, sysid: int = 1) -> None:
        self.conn = mavutil.mavlink_connection(
            f"udpout:127.0.0.1:{port}", source_system=SYSID, source_component=COMPID
        )
        # The vehicle's own dialect, so its own messages decode.
        self.conn.mav = d.MAVLink(self.conn, srcSystem=SYSID, srcComponent=COMPID)
        self.conn.mav.robust_parsing = True
        widen_receive_buffer(self.conn)
        self.mav = self.conn.mav
        self.sysid = sysid
        self.texts: list[str] = []  # every STATUSTEXT seen, for the failure messages
        self.time_boot_s = 0.0  # the vehicle clock (the simulation's, in a simulation)
        self._hello_at = 0.0

    def _hello(self) -> None:
        """Once a second, a TIMESYNC request addressed to the vehicle's autopilot: the
        vehicle answers it to us alone and forwards it nowhere (see the module's text)."""
        now = time.monotonic()
        if now - self._hello_at >= 1.0:
            self._hello_at = now
            self.mav.timesync_send(0, time.monotonic_ns(), self.sysid, 1)

    def _note(self, msg: Any) -> None:
        if msg.get_type() == "STATUSTEXT":
            self.texts.append(msg.text)
        t_ms = getattr(msg, "time_boot_ms", None)
        if t_ms is not None and msg.get_srcSystem() == self.sysid:
            self.time_boot_s = max(self.time_boot_s, t_ms / 1000.0)

    def said(self) -> str:
        """The vehicle's last texts, for a failure's message."""
        return f"; the vehicle said: {self.texts[-8:]}"

    def recv(self, timeout_s: float = 0.2) -> Any:
        """The next message from the vehicle, or None; keeps the vehicle hearing us."""
        self._hello()
        msg = self.conn.recv_match(blocking=True, timeout=timeout_s)
        if msg is None or msg.get_type() == "BAD_DATA":
            return None
        self._note(msg)
        return msg if msg.get_srcSystem() == self.sysid else None

    def drain(self) -> None:
        """Read what piled up while nobody polled (old heartbeats would answer for now)."""
        for _ in range(100_000):
            msg = self.conn.recv_match(blocking=False)
            if msg is None:
                return
            self._note(msg)

    def until(self, check: Callable[[Any], Any], timeout_s: float, what: str) -> Any:
        """The first truthy ``check(msg)`` within ``timeout_s`` wall seconds."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            msg = self.recv()
            if msg is not None and (value := check(msg)):
                return value
        raise VehicleError(
            f"within {timeout_s:g} s, no {what}; the vehicle said: {self.texts[-8:]}"
        )

    def connect(self, timeout_s: float) -> Any:
        """Wait for the vehicle's heartbeat (it sends once it has heard us)."""
        return self.until(lambda m: m.get_type() == "HEARTBEAT" and m, timeout_s, "HEARTBEAT")

    def command(self, command: int, *params: float, timeout_s: float = 30.0) -> Any:
        """COMMAND_LONG until its final COMMAND_ACK; VehicleError unless accepted."""
        values = [*params, 0, 0, 0, 0, 0, 0, 0][:7]
        self.mav.command_long_send(self.sysid, 1, command, 0, *values)

        def final(m: Any) -> Any:
            done = m.get_type() == "COMMAND_ACK" and m.command == command
            return m if done and m.result != d.MAV_RESULT_IN_PROGRESS else None

        ack = self.until(final, timeout_s, f"COMMAND_ACK for command {command}")
        if ack.result != d.MAV_RESULT_ACCEPTED:
            name = d.enums["MAV_RESULT"][ack.result].name
            raise VehicleError(
                f"command {command} refused: {name}; the vehicle said: {self.texts[-8:]}"
            )
        return ack

    def mode(self, msg: Any) -> FlightMode | None:
        """The vehicle's mode in a HEARTBEAT of its autopilot (PX4's custom_mode packing,
        ArduPlane's numbers when it reports generic)."""
        if msg.get_type() != "HEARTBEAT" or msg.get_srcComponent() != 1:
            return None
        if msg.autopilot == d.MAV_AUTOPILOT_GENERIC:
            return from_generic(msg.custom_mode)
        return from_px4((msg.custom_mode >> 16) & 0xFF, (msg.custom_mode >> 24) & 0xFF)

    def upload_plan(self, plan: str | Path, timeout_s: float = 30.0) -> dict[int, int]:
        """Upload a QGroundControl .plan's mission, fence and rally points (the ones it
        has) with the mission protocol; returns the item count per mission type."""
        counts = {}
        for mission_type, items in load_plan(plan).items():
            if items or mission_type == d.MAV_MISSION_TYPE_MISSION:
                self._upload(mission_type, items, timeout_s)
                counts[mission_type] = len(items)
        return counts

    def _upload(self, mission_type: int, items: list[Any], timeout_s: float) -> None:
        self.mav.mission_count_send(self.sysid, 1, len(items), mission_type)
        wanted = ("MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK")
        while True:
            msg = self.until(
                lambda m: m.get_type() in wanted and m.mission_type == mission_type and m,
                timeout_s, f"mission request (type {mission_type})",
            )  # fmt: skip
            if msg.get_type() == "MISSION_ACK":
                if msg.type != d.MAV_MISSION_ACCEPTED:
                    name = d.enums["MAV_MISSION_RESULT"][msg.type].name
                    raise VehicleError(f"plan refused: {name}{self.said()}")
                return
            i = items[msg.seq]
            self.mav.mission_item_int_send(
                self.sysid, 1, msg.seq, i.frame, i.command, int(msg.seq == 0), i.autocontinue,
                i.param1, i.param2, i.param3, i.param4, i.x, i.y, i.z, mission_type,
            )  # fmt: skip

    def close(self) -> None:
        self.conn.close()
