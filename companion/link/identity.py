"""Who the vehicle is: HEARTBEAT, AUTOPILOT_VERSION, PROTOCOL_VERSION.

The state the heartbeat reports (armed, mode, system status) is set by the link plug-in
from the bus; this service only turns it into messages at 1 Hz and on request.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from typing import Any

from companion import __version__
from companion.link.codec import dialect as mav_dialect
from companion.link.microservice import Outgoing, Peer
from companion.link.px4_compat import PX4_COMPAT_VERSION

HEARTBEAT_PERIOD_S = 1.0


def version_number(version: str) -> int:
    """MAVLink's packed version: major<<24 | minor<<16 | patch<<8 | FIRMWARE_VERSION_TYPE."""
    parts = [int(p) if p.isdigit() else 0 for p in version.split(".")[:3]]
    major, minor, patch = [*parts, 0, 0, 0][:3]
    official = mav_dialect.FIRMWARE_VERSION_TYPE_OFFICIAL
    return (major << 24) | (minor << 16) | (patch << 8) | official


@dataclass
class VehicleState:
    """What the heartbeat tells the world."""

    armed: bool = False
    custom_mode: int = 0
    mode_flags: int = 0  # MAV_MODE_FLAG bits of the mode (auto, guided, stabilize, manual)
    system_status: int = mav_dialect.MAV_STATE_STANDBY
    # False while the link has not read the vehicle's mode yet: no heartbeat then. A ground
    # station bears a second without one; a false mode it shows, and acts on.
    known: bool = True


class IdentityService:
    """Heartbeat on its own timer, and the identity messages asked for at connect."""

    handles = frozenset[str]()

    def __init__(self, mav: Any, sysid: int, autopilot: int, capabilities: int) -> None:
        self.mav = mav
        self.sysid = sysid
        self.autopilot = autopilot
        self.capabilities = capabilities
        self.state = VehicleState()
        self._next_heartbeat = 0.0
        self.uid = int.from_bytes(
            hashlib.sha1(f"companion-{sysid}".encode()).digest()[:8], "little"
        )

    def heartbeat(self) -> Any:
        d = mav_dialect
        base = d.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | self.state.mode_flags
        if self.state.armed:
            base |= d.MAV_MODE_FLAG_SAFETY_ARMED
        return self.mav.heartbeat_encode(
            d.MAV_TYPE_FIXED_WING,
            self.autopilot,
            base,
            self.state.custom_mode,
            self.state.system_status,
        )

    def autopilot_version(self) -> Any:
        ours = version_number(__version__)
        flight = ours
        if self.autopilot == mav_dialect.MAV_AUTOPILOT_PX4:  # the PX4 behaviour we follow
            flight = version_number(".".join(map(str, PX4_COMPAT_VERSION)))
        return self.mav.autopilot_version_encode(
            self.capabilities, flight, ours, 0, 0, b"\0" * 8, b"\0" * 8, b"\0" * 8, 0, 0, self.uid
        )

    def protocol_version(self) -> Any:
        return self.mav.protocol_version_encode(200, 100, 200, b"\0" * 8, b"\0" * 8)

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        return []

    def tick(self, now_s: float) -> list[Outgoing]:
        if now_s < self._next_heartbeat or not self.state.known:
            return []
        # On time or a little late: keep the 1 Hz phase. A period or more late (the first
        # one, or after a stall): one heartbeat now and the phase starts again, never a
        # second one to catch up (a ground station counts heartbeats as the link's rate).
        self._next_heartbeat += HEARTBEAT_PERIOD_S
        if self._next_heartbeat <= now_s:
            self._next_heartbeat = now_s + HEARTBEAT_PERIOD_S
        return [Outgoing(self.heartbeat(), None)]

    def next_due(self) -> float:
        return self._next_heartbeat if self.state.known else math.inf
