"""Frames in, messages routed: parsers per remote, forwarding, dispatch, sending.

Messages addressed to another system are forwarded to the endpoints where that system
was heard (every other endpoint if unknown), as mavlink-router does; broadcasts are both
forwarded and handled. Replies go to the endpoint of the peer that asked.
"""

from __future__ import annotations

import logging
import math
import struct
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from companion.link.codec import StreamParser, new_encoder, new_parser
from companion.link.endpoints import Endpoint, Remote, UdpOut, default_budget
from companion.link.link_budget import LinkBudget
from companion.link.microservice import Outgoing, Peer, Service
from companion.link.signing import configure_parser, shared_state, signing_encoder
from companion.link.snapshot import Snapshot
from companion.link.stream_schedule import BATCH_S, StreamSchedule
from companion.link.telemetry import STREAMS
from companion.link.tlog import TlogWriter

log = logging.getLogger(__name__)


@dataclass
class LinkCounters:
    ok: int = 0  # frames decoded
    bad: int = 0  # rejections: CRC failures, truncated frames, garbage, refused signatures
    bad_signature: int = 0  # of those: not signed with our key where it had to be
    replayed: int = 0  # and: well signed but not newer than its stream's last (or stale)
    forwarded: int = 0
    foreign: int = 0  # addressed to another system
    stream_errors: int = 0  # telemetry samples that could not be encoded


def _target_system(msg: Any) -> int:
    """The system a message is addressed to (0: every one). MANUAL_CONTROL names it
    ``target``; read as a broadcast, a joystick flood on one link was forwarded onto every
    other, and crowded a 57600-baud radio's telemetry off."""
    target = getattr(msg, "target_system", None)
    if target is None and msg.get_type() == "MANUAL_CONTROL":
        target = msg.target
    return target or 0


class LinkRouter:
    """Routing and dispatch for all endpoints of the link."""

    def __init__(
        self,
        mav: Any,
        endpoints: list[Endpoint],
        services: list[Service],
        signing_key: bytes | None = None,
    ) -> None:
        self.mav = mav
        self.endpoints = endpoints
        self.services: list[Service] = []
        self._timers: list[Callable[[], float]] = []  # the services' next_due
        self.parsers: dict[tuple[int, Remote], StreamParser] = {}
        self.routes: dict[int, set[int]] = {}  # sysid → endpoint indexes it was heard on
        self.schedules = [StreamSchedule() for _ in endpoints]
        self.budgets = [LinkBudget(default_budget(e)) for e in endpoints]
        self.tlogs = [TlogWriter(e.options.tlog) if e.options.tlog else None for e in endpoints]
        self.counters = LinkCounters()
        self.signing = shared_state(signing_key) if signing_key else None
        self.packers = [self._packer(i, e, signing_key) for i, e in enumerate(endpoints)]
        self.by_type: dict[str, list[Service]] = {}
        for service in services:
            self.add_service(service)

    def _packer(self, index: int, endpoint: Endpoint, key: bytes | None) -> Any:
        """The encoder that frames what goes out of an endpoint (signed or not)."""
        if endpoint.options.signing == "off" or key is None:
            return self.mav
        packer = new_encoder(self.mav.srcSystem, self.mav.srcComponent)
        signing_encoder(packer, key, link_id=index + 1)
        return packer

    def add_service(self, *services: Service) -> None:
        for service in services:
            if service not in self.services:
                self.services.append(service)
                if (timer := getattr(service, "next_due", None)) is not None:
                    self._timers.append(timer)
            for name in service.handles:
                self.by_type.setdefault(name, []).append(service)

    def receive(self, endpoint: Endpoint, fd: int, now_s: float) -> None:
        index = self.endpoints.index(endpoint)
        for remote, data in endpoint.read_ready(fd):
            parser = self.parsers.get((index, remote))
            if parser is None:
                parser = self.parsers[(index, remote)] = new_parser()
                configure_parser(parser.mav, self.signing, endpoint.options.signing)
            c = parser.counters
            before = c.rejected, c.bad_signature, c.replayed
            # A datagram holds whole frames: one cut short at its end never completes.
            messages = parser.parse_buffer(data, final=isinstance(endpoint, UdpOut))
            self.counters.bad += c.rejected - before[0]
            self.counters.bad_signature += c.bad_signature - before[1]
            self.counters.replayed += c.replayed - before[2]
            for msg in messages:
                self._route(msg, index, now_s)

    def _route(self, msg: Any, index: int, now_s: float) -> None:
        self.counters.ok += 1
        tlog = self.tlogs[index]
        if tlog is not None:
            tlog.write(bytes(msg.get_msgbuf()))
        if msg.get_type() == "RADIO_STATUS":
            self.budgets[index].radio_status(msg.txbuf)
        sysid, compid = msg.get_srcSystem(), msg.get_srcComponent()
        if sysid == self.mav.srcSystem:
            return  # our own traffic looped back by another router
        self.routes.setdefault(sysid, set()).add(index)
        target = _target_system(msg)
        if target not in (0, self.mav.srcSystem):
            self.counters.foreign += 1
            self._forward(msg, index, self.routes.get(target))
            return
        if target == 0:
            self._forward(msg, index, None)
        peer = Peer(sysid, compid, index)
        out: list[Outgoing] = []
        for service in self.by_type.get(msg.get_type(), []):
            out += service.handle(msg, peer, now_s)
        self.send(out, now_s)

    def _forward(self, msg: Any, came_from: int, to: set[int] | None) -> None:
        raw = bytes(msg.get_msgbuf())
        for i, endpoint in enumerate(self.endpoints):
            if i != came_from and (to is None or i in to):
                endpoint.send(raw)
                self.counters.forwarded += 1

    def _emit(self, index: int, raw: bytes, priority: bool, now_s: float) -> bool:
        budget = self.budgets[index]
        if priority:
            budget.take_priority(len(raw), now_s)
        elif not budget.take_telemetry(len(raw), now_s):
            return False
        self.endpoints[index].send(raw)
        tlog = self.tlogs[index]
        if tlog is not None:
            tlog.write(raw)
        return True

    def send(self, out: list[Outgoing], now_s: float) -> None:
        """Frame and send; telemetry only where the endpoint's budget allows."""
        for item in out:
            targets = range(len(self.endpoints)) if item.to is None else [item.to.endpoint]
            frames: dict[int, bytes] = {}
            for index in targets:
                packer = self.packers[index]
                if id(packer) not in frames:
                    frames[id(packer)] = self._pack(packer, item.msg)
                self._emit(index, frames[id(packer)], item.priority, now_s)
            self.mav.seq = (self.mav.seq + 1) % 256

    def tick(self, now_s: float) -> list[Outgoing]:
        out: list[Outgoing] = []
        for service in self.services:
            out += service.tick(now_s)
        return out

    def stream_telemetry(self, snapshot: Snapshot, now_s: float, nav_at_s: float) -> None:
        for index, endpoint in enumerate(self.endpoints):
            if not endpoint.has_remote():
                continue
            for msg_id in self.schedules[index].due(now_s, nav_at_s, BATCH_S):
                try:
                    msg = STREAMS[msg_id].build(self.mav, snapshot)
                    # Framed once, for this endpoint; values out of a field's range raise here.
                    raw = None if msg is None else self._pack(self.packers[index], msg)
                except (ValueError, OverflowError, struct.error) as exc:
                    self.counters.stream_errors += 1
                    log.debug("stream %s: %s", STREAMS[msg_id].name, exc)
                    continue
                if raw is None:
                    continue
                self.mav.seq = (self.mav.seq + 1) % 256
                if not self._emit(index, raw, False, now_s):
                    # Out of budget: stop here rather than let smaller, younger streams slip
                    # past, or a large frame would never find enough budget left for it.
                    break
                self.schedules[index].mark_sent(msg_id, now_s)

    def _pack(self, packer: Any, msg: Any) -> bytes:
        """Frame a message with the vehicle's current sequence number (signed or not)."""
        packer.seq = self.mav.seq
        return msg.pack(packer)

    def next_due(self, nav_known: bool = True) -> float:
        times = [s.next_time(nav_known) for s in self._streaming()]
        return min([*times, *(timer() for timer in self._timers), math.inf])

    def _streaming(self) -> list[StreamSchedule]:
        """The schedules of the endpoints that have someone to send to. One nobody has
        spoken to yet (udpin, tcpin) streams nothing: its streams, due since its start,
        made every wait a zero one (the link spun) until a ground station came."""
        pairs = zip(self.endpoints, self.schedules, strict=True)
        return [schedule for endpoint, schedule in pairs if endpoint.has_remote()]

    def next_wake(
        self, now_s: float, max_wait_s: float, nav_known: bool = True
    ) -> tuple[float, bool]:
        """How long the link may sleep (at most ``max_wait_s``), and whether a navigation
        state should end the sleep: only once a stream that carries it is due on an
        endpoint that has someone to send to (the navigator publishes five times as often
        as ATTITUDE goes out, and a wake-up costs the whole step). Before the first state
        (``nav_known`` false) the streams that carry one wait for it without a timer, and
        that first state ends the sleep."""
        if not nav_known:
            return max(0.0, min(max_wait_s, self.next_due(False) - now_s)), True
        nav_due = min((s.nav_due() for s in self._streaming()), default=math.inf)
        until = self.next_due() if now_s >= nav_due else min(self.next_due(), nav_due)
        return max(0.0, min(max_wait_s, until - now_s)), now_s >= nav_due

    def close(self) -> None:
        for tlog in self.tlogs:
            if tlog is not None:
                tlog.close()
