"""The log download microservice: the on-board flight logs listed, sent and erased.

As QGroundControl's Log Download page and MAVProxy's ``log`` module use it:
LOG_REQUEST_LIST (a range of ids) → one LOG_ENTRY per log (id, size, time), ids from 0 in
the order the logs were started (``num_logs`` 0 when there is none); LOG_REQUEST_DATA
(id, offset, count) → LOG_DATA of 90 bytes each from that offset, the last one shorter.
A request from the end (up to the next 90-byte boundary) gets a LOG_DATA with ``count`` 0:
MAVProxy asks there once it holds every packet and, on a log of whole packets, waits for
that answer. Nothing else gets one: MAVProxy ends its download at a count-0 packet
whatever it still lacks, so a packet lost on the way (a full receive buffer on a busy
machine) would be saved as 90 zero bytes. Without it, MAVProxy finds the hole after 0.7 s
of silence, asks for it, and then asks from the end. A request overlapping the range under
way replaces it (QGroundControl, after a silence, asks again from its first hole); one
beside it waits its turn (MAVProxy asks for up to twenty holes at once); LOG_REQUEST_END
stops. LOG_ERASE removes every log but the one being written, and is refused while armed.

The data goes out at a share of the link's byte budget, paced here, so telemetry and
command answers keep the rest. Requests that cannot be served (unknown id, offset past
the end, empty ranges) are refused: counted, nothing sent.
"""

from __future__ import annotations

import logging
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

from companion.flight_log import LogDirectory
from companion.link.microservice import Outgoing, Peer

log = logging.getLogger(__name__)

CHUNK = 90  # LOG_DATA's data field
FRAME_BYTES = 109  # a full LOG_DATA frame in MAVLink 2: header 10, payload 97, CRC 2
ENTRY_BYTES = 26
SHARE = 0.5  # of the link's byte budget; telemetry keeps the rest
BURST_S = 0.05  # the pacing bucket holds this many seconds of log data
MAX_FRAMES_PER_TICK = 64  # one link step stays short whatever the budget
MAX_UINT32 = 0xFFFFFFFF
MAX_QUEUED = 64  # ranges waiting behind the one under way


@dataclass(frozen=True)
class LogEntry:
    """One log as listed: its file, size in bytes and start time (UTC seconds, 0 unknown)."""

    path: Path
    size: int
    time_utc: int


@dataclass
class _Range:
    ofs: int  # next byte to send
    end: int  # one past the last byte to send
    eof_marker: bool  # a count-0 LOG_DATA at ``end`` once the data is out

    def overlaps(self, other: _Range) -> bool:
        # Ranges that only touch do not: a station asking for each lost packet on its own
        # had every second request drop the one before it.
        return self.ofs < other.end and other.ofs < self.end


@dataclass
class _Transfer:
    peer: Peer
    log_id: int
    stream: BinaryIO
    now: _Range
    queued: deque[_Range]


class LogTransferService:
    """Serves the logs of a LogDirectory to ground stations, paced by the link's budget."""

    handles = frozenset({"LOG_REQUEST_LIST", "LOG_REQUEST_DATA", "LOG_ERASE", "LOG_REQUEST_END"})

    def __init__(
        self,
        mav: Any,
        logs: LogDirectory,
        sysid: int,
        compid: int,
        rate_bytes_s: Callable[[int], float],
        armed: Callable[[], bool] = lambda: False,
    ) -> None:
        self.mav = mav
        self.logs = logs
        self.sysid = sysid
        self.compid = compid
        self.rate_bytes_s = rate_bytes_s  # endpoint index → its budget now
        self.armed = armed
        self.on_refusal: Callable[[str], None] = lambda text: None
        self.entries: list[LogEntry] | None = None  # as last listed; ids index it
        self.listing: deque[tuple[int, Peer]] = deque()
        self.transfer: _Transfer | None = None
        self.tokens = 0.0
        self.last_s: float | None = None
        self.refused = 0
        self.rejected_target = 0  # for another component of this system
        self.bytes_sent = 0
        self.erased = 0

    def _for_us(self, msg: Any) -> bool:
        return msg.target_system in (0, self.sysid) and msg.target_component in (0, self.compid)

    def _refuse(self, why: str) -> list[Outgoing]:
        self.refused += 1
        log.info("log transfer: %s", why)
        return []

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        if not self._for_us(msg):
            self.rejected_target += 1
            return []
        kind = msg.get_type()
        if kind == "LOG_REQUEST_LIST":
            return self._list(msg.start, msg.end, peer, now_s)
        if kind == "LOG_REQUEST_DATA":
            return self._request(msg.id, msg.ofs, msg.count, peer, now_s)
        if kind == "LOG_REQUEST_END":
            self._stop()
            return []
        return self._erase()

    def _snapshot(self) -> list[LogEntry]:
        entries = []
        for path in self.logs.files():
            try:
                stat = path.stat()
            except OSError:
                continue  # removed while listing
            entries.append(LogEntry(path, min(stat.st_size, MAX_UINT32), int(stat.st_mtime)))
        self.entries = entries
        return entries

    def _entry(self, log_id: int, entries: list[LogEntry]) -> Outgoing:
        e = entries[log_id]
        msg = self.mav.log_entry_encode(log_id, len(entries), len(entries) - 1, e.time_utc, e.size)
        return Outgoing(msg, None)

    def _list(self, start: int, end: int, peer: Peer, now_s: float) -> list[Outgoing]:
        if start > end:
            return self._refuse(f"LOG_REQUEST_LIST {start}..{end}: empty range")
        entries = self._snapshot()
        if not entries:
            return [Outgoing(self.mav.log_entry_encode(0, 0, 0, 0, 0), peer)]
        if start >= len(entries):
            return self._refuse(f"LOG_REQUEST_LIST from {start}: only {len(entries)} logs")
        last = min(end, len(entries) - 1)
        # A station asking again restarts its own list; another station's goes on.
        others = (item for item in self.listing if item[1] != peer)
        self.listing = deque([*others, *((i, peer) for i in range(start, last + 1))])
        return self.tick(now_s)

    def _request(self, log_id: int, ofs: int, count: int, peer: Peer, now_s: float) -> list[Any]:
        entries = self.entries if self.entries is not None else self._snapshot()
        if log_id >= len(entries):
            return self._refuse(f"LOG_REQUEST_DATA for log {log_id}: {len(entries)} logs")
        if count == 0:
            return self._refuse(f"LOG_REQUEST_DATA for log {log_id}: no bytes asked")
        path = entries[log_id].path
        try:
            stream = path.open("rb")
            size = min(path.stat().st_size, MAX_UINT32)
        except OSError as exc:
            return self._refuse(f"log {log_id} ({path.name}) cannot be read: {exc}")
        if ofs > -(-size // CHUNK) * CHUNK:
            stream.close()
            return self._refuse(f"LOG_REQUEST_DATA for log {log_id}: offset {ofs} > size {size}")
        # From the end (MAVProxy asks there once it has every packet): just the marker.
        eof_marker = ofs >= size
        end = max(ofs, min(size, ofs + count))
        self._add(_Range(ofs, end, eof_marker), log_id, peer, stream)
        return self.tick(now_s)

    def _add(self, wanted: _Range, log_id: int, peer: Peer, stream: BinaryIO) -> None:
        t = self.transfer
        if t is None or t.log_id != log_id:
            self._stop()
            self.transfer = _Transfer(peer, log_id, stream, wanted, deque())
            return
        stream.close()  # the same log: the open one serves
        t.peer = peer
        t.queued = deque(r for r in t.queued if not r.overlaps(wanted))
        if t.now.overlaps(wanted):
            t.now = wanted
        elif len(t.queued) < MAX_QUEUED:
            t.queued.append(wanted)
        else:
            self.refused += 1

    def _stop(self) -> None:
        if self.transfer is not None:
            self.transfer.stream.close()
            self.transfer = None

    def _erase(self) -> list[Outgoing]:
        if self.armed():
            self.on_refusal("Logs not erased: armed")
            return self._refuse("LOG_ERASE while armed")
        self._stop()
        self.listing.clear()
        removed = self.logs.erase()
        self.erased += len(removed)
        self.entries = None
        return []

    def _refill(self, now_s: float, rate: float) -> None:
        capacity = max(FRAME_BYTES, rate * BURST_S)
        if self.last_s is None:
            self.tokens = capacity
        else:
            self.tokens = min(capacity, self.tokens + max(0.0, now_s - self.last_s) * rate)
        self.last_s = now_s

    def _served(self) -> Peer | None:
        """Whom the pacing serves now: the listing's asker, else the transfer's; None: idle."""
        if self.listing:
            return self.listing[0][1]
        return self.transfer.peer if self.transfer is not None else None

    def tick(self, now_s: float) -> list[Outgoing]:
        peer = self._served()
        if peer is None:
            self.last_s = None  # idle: the next transfer starts with a full bucket
            return []
        self._refill(now_s, self.rate_bytes_s(peer.endpoint) * SHARE)
        out: list[Outgoing] = []
        entries = self.entries or []
        while self.listing and self.tokens >= ENTRY_BYTES:
            log_id, to = self.listing.popleft()
            if log_id < len(entries):
                out.append(Outgoing(self._entry(log_id, entries).msg, to))
                self.tokens -= ENTRY_BYTES
        while self.transfer is not None and self.tokens >= FRAME_BYTES:
            if len(out) >= MAX_FRAMES_PER_TICK:
                break
            out += self._next_data()
        return out

    def _next_data(self) -> list[Outgoing]:
        t = self.transfer
        assert t is not None
        r = t.now
        if r.ofs >= r.end:
            out = []
            if r.eof_marker and t.queued:
                # MAVProxy ends its download at a count-0 packet, holes or not: the holes it
                # asked for meanwhile go first (a log of whole packets saved with a gap).
                t.queued.append(_Range(r.end, r.end, eof_marker=True))
            elif r.eof_marker:
                msg = self.mav.log_data_encode(t.log_id, r.end, 0, bytes(CHUNK))
                out.append(Outgoing(msg, t.peer))
                self.tokens -= FRAME_BYTES
            self._next_range()
            return out
        try:
            t.stream.seek(r.ofs)
            data = t.stream.read(min(CHUNK, r.end - r.ofs))
        except OSError as exc:
            log.warning("log %d: read failed at %d: %s", t.log_id, r.ofs, exc)
            data = b""
        if not data:  # the file shrank or vanished: nothing more of this range
            self._next_range()
            return []
        msg = self.mav.log_data_encode(t.log_id, r.ofs, len(data), data.ljust(CHUNK, b"\0"))
        r.ofs += len(data)
        self.tokens -= FRAME_BYTES
        self.bytes_sent += len(data)
        return [Outgoing(msg, t.peer)]

    def _next_range(self) -> None:
        t = self.transfer
        assert t is not None
        if t.queued:
            t.now = t.queued.popleft()
        else:
            self._stop()

    def next_due(self) -> float:
        """When the pacing allows the next frame (the link waits no longer than that)."""
        peer = self._served()
        if self.last_s is None or peer is None:
            return float("inf")
        rate = self.rate_bytes_s(peer.endpoint) * SHARE
        missing = max(0.0, FRAME_BYTES - self.tokens)
        return self.last_s + (missing / rate if rate > 0 else 1.0)
