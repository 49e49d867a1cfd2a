"""TIMESYNC replies, so a ground station can estimate the link delay and clock offset."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from companion.link.microservice import Outgoing, Peer


class TimesyncService:
    """Answers a TIMESYNC request (tc1 == 0) with our time in tc1 and its ts1 echoed.

    A request may be broadcast (target 0) or addressed to one system and component; one
    for another component of this system is not ours to answer (counted in
    ``rejected_target``). The reply is addressed to the requester, as the protocol asks.
    """

    handles = frozenset({"TIMESYNC"})

    def __init__(self, mav: Any, now_ns: Callable[[], int], sysid: int, compid: int = 1) -> None:
        self.mav = mav
        self.now_ns = now_ns
        self.sysid = sysid
        self.compid = compid
        self.rejected_target = 0

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        if msg.tc1 != 0:
            return []  # a reply to somebody else's request
        target = (msg.target_system, msg.target_component)
        if target[0] not in (0, self.sysid) or target[1] not in (0, self.compid):
            self.rejected_target += 1
            return []
        reply = self.mav.timesync_encode(self.now_ns(), msg.ts1, peer.sysid, peer.compid)
        return [Outgoing(reply, peer)]

    def tick(self, now_s: float) -> list[Outgoing]:
        return []
