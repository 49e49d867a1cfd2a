"""What every vehicle-side MAVLink microservice looks like (one service, one unit).

A service is pure: decoded messages and ``now_s`` (monotonic seconds) in, messages to
send out. The link plug-in owns the transports and the bus and dispatches by message type.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, Protocol


@dataclass(frozen=True)
class Peer:
    """Who sent a message: its (sysid, compid) and the endpoint it came in on."""

    sysid: int
    compid: int
    endpoint: int


@dataclass(frozen=True)
class Outgoing:
    """A message to send to one peer's endpoint, or to every endpoint (``to=None``)."""

    msg: Any  # a pymavlink MAVLink_message built with the encoder
    to: Peer | None
    priority: bool = True  # protocol replies go ahead of telemetry


class Service(Protocol):
    """A MAVLink microservice of the vehicle."""

    handles: frozenset[str]  # MAVLink message type names, e.g. {"PARAM_REQUEST_LIST"}

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        """React to one message addressed to the vehicle."""
        ...

    def tick(self, now_s: float) -> list[Outgoing]:
        """Timeouts, retries and paced streaming."""
        ...


def refused_count(services: Iterable[object]) -> int:
    """Well-formed input the services refused: by its rules (``refused``) or because it was
    addressed to another component of this system (``rejected_target``). Another system's
    traffic never reaches them: the router forwards it."""
    return sum(getattr(s, "refused", 0) + getattr(s, "rejected_target", 0) for s in services)
