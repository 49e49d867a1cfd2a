"""GPS_RTCM_DATA: a ground station's RTK corrections, joined and handed to the GPS.

QGroundControl (with an RTK base station on its computer), MAVSDK's Rtk plug-in and
MAVProxy send each RTCM message in one GPS_RTCM_DATA, or, when longer than 180 bytes, in
up to four fragments. ``flags`` bit 0 says fragmented, bits 1-2 the fragment's place and
bits 3-7 a sequence number shared by one message's fragments. A message goes on to the
receiver only whole, as MAVLink asks, so that nothing else written to the receiver's port
lands inside it: when all four fragments are in, or every fragment up to the first one
shorter than 180 bytes. One whose length is a multiple of 180 and under four fragments
has no short fragment; it is known whole when the next message's first fragment comes,
and is passed on then. A message missing a fragment when the next one begins is dropped
and counted, as is a fragment that says more than 180 bytes.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from companion.link.microservice import Outgoing, Peer
from companion.messages import GpsInject

FRAGMENT_BYTES = 180
MAX_FRAGMENTS = 4


class RtcmReassembler:
    """Joins GPS_RTCM_DATA fragments into whole RTCM messages (pure: no bus, no clock)."""

    def __init__(self) -> None:
        self.messages = 0  # whole messages handed on
        self.dropped = 0  # messages given up for a missing or malformed fragment
        self._seq: int | None = None  # the message being gathered
        self._parts: dict[int, bytes] = {}
        self._dead: int | None = None  # a message already dropped: its late fragments too

    def feed(self, flags: int, length: int, data: bytes) -> list[bytes]:
        """The whole messages this fragment (``length`` bytes of ``data`` said) completes:
        often none, at most two."""
        seq, place = flags >> 3, (flags >> 1) & 3
        broken = length > FRAGMENT_BYTES or length > len(data)
        if not flags & 1:  # a message in one piece
            out, self._dead = self._flush(), None
            self.dropped += broken
            return out if broken else [*out, self._done(data[:length])]
        if seq == self._dead:
            return []
        out = self._flush() if seq != self._seq else []
        if broken:  # a fragment that says more than it holds: its message is lost
            return [*out, *self._give_up(seq)]
        data = data[:length]
        self._seq, self._dead = seq, None
        if place in self._parts:  # a place filled twice: not one message
            return [*out, *self._give_up(seq)]
        self._parts[place] = data
        if length < FRAGMENT_BYTES or len(self._parts) == MAX_FRAGMENTS:
            whole = self._joined(short_ends=True)
            if whole is None:
                return [*out, *self._give_up(seq)]
            self._seq, self._parts = None, {}
            return [*out, self._done(whole)]
        return out

    def _give_up(self, seq: int) -> list[bytes]:
        self._seq, self._parts, self._dead = None, {}, seq
        self.dropped += 1
        return []

    def _flush(self) -> list[bytes]:
        """What was gathered before another message began: whole only as full fragments
        from the first on (a message of n x 180 bytes); else dropped."""
        if self._seq is None:
            return []
        whole = self._joined(short_ends=False)
        self._seq, self._parts = None, {}
        if whole is None:
            self.dropped += 1
            return []
        return [self._done(whole)]

    def _joined(self, short_ends: bool) -> bytes | None:
        """The fragments as one message if they are one: every place from the first, each
        full but the last, which may be short only when ``short_ends``."""
        places = sorted(self._parts)
        full = all(len(self._parts[p]) == FRAGMENT_BYTES for p in places[:-1])
        last_ok = short_ends or len(self._parts[places[-1]]) == FRAGMENT_BYTES
        if places != list(range(len(places))) or not full or not last_ok:
            return None
        return b"".join(self._parts[p] for p in places)

    def _done(self, data: bytes) -> bytes:
        self.messages += 1
        return data


class RtcmInjectService:
    """The link's side: GPS_RTCM_DATA in, whole messages on ``link/gps_inject``."""

    handles = frozenset({"GPS_RTCM_DATA"})

    def __init__(self, publish: Callable[[GpsInject], None], now_us: Callable[[], int]) -> None:
        self.publish = publish
        self.now_us = now_us
        self.joiner = RtcmReassembler()

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        for whole in self.joiner.feed(msg.flags, msg.len, bytes(msg.data)):
            if whole:  # an empty message is nothing to write
                self.publish(GpsInject.of(self.now_us(), whole))
        return []

    @property
    def refused(self) -> int:
        """Messages dropped for a missing or malformed fragment: the ``refused`` column of
        ``companion status``, beside the commands refused by their rules."""
        return self.joiner.dropped

    def tick(self, now_s: float) -> list[Outgoing]:
        return []
