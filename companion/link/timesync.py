"""TIMESYNC replies, so a ground station can estimate the link delay and clock offset."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from companion.link.service import Outgoing, Peer


class TimesyncService:
    """Answers a TIMESYNC request (tc1 == 0) with our time in tc1 and its ts1 echoed."""

    handles = frozenset({"TIMESYNC"})

    def __init__(self, mav: Any, now_ns: Callable[[], int]) -> None:
        self.mav = mav
        self.now_ns = now_ns

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        if msg.tc1 != 0:
            return []  # a reply to somebody else's request
        reply = self.mav.timesync_encode(self.now_ns(), msg.ts1)
        return [Outgoing(reply, peer)]

    def tick(self, now_s: float) -> list[Outgoing]:
        return []
