"""The mission microservice, vehicle side, for missions, fences and rally points.

Upload: MISSION_COUNT, then the vehicle asks for each item in order (MISSION_REQUEST_INT),
re-asking after a timeout, and commits the whole list atomically only when every item
arrived and can be flown; otherwise the old list stays and MISSION_ACK says why.
Download: MISSION_REQUEST_LIST → MISSION_COUNT, then items on request (INT or legacy).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from companion.control.mission.fence import Fence, honoured
from companion.control.mission.items import (
    MISSION_TYPES,
    TAKEOFF_NOT_FIRST,
    MissionItem,
    first_refusal,
    not_carried_note,
)
from companion.control.mission.mission_files import MissionStore
from companion.control.prearm import PlanVerdicts
from companion.link.command_service import command_name
from companion.link.microservice import Outgoing, Peer
from companion.link.refusal_texts import RefusalTexts
from companion.link.snapshot import Snapshot
from companion.messages import MissionState
from mavlink_dialect import companion as d

log = logging.getLogger(__name__)

ITEM_TIMEOUT_S = 0.5  # re-ask for an item after this long
MAX_RETRIES = 5
MAX_ITEMS = 1000


def mission_current_message(mav: Any, seq: int, total: int) -> Any:
    """MISSION_CURRENT for the stored mission (the executor will add the running states)."""
    state = d.MISSION_STATE_NO_MISSION if total == 0 else d.MISSION_STATE_NOT_STARTED
    return mav.mission_current_encode(seq, total, state)


@dataclass
class _Upload:
    peer: Peer
    mission_type: int
    count: int
    items: list[MissionItem] = field(default_factory=list)
    asked_at: float = 0.0
    retries: int = 0


class MissionService:
    """Transfers missions between ground stations and the MissionStore."""

    handles = frozenset(
        {
            "MISSION_COUNT",
            "MISSION_ITEM_INT",
            "MISSION_ITEM",
            "MISSION_REQUEST_LIST",
            "MISSION_REQUEST_INT",
            "MISSION_REQUEST",
            "MISSION_CLEAR_ALL",
            "MISSION_SET_CURRENT",
            "MISSION_ACK",
        }
    )

    def __init__(self, mav: Any, store: MissionStore, sysid: int, compid: int = 1) -> None:
        self.mav = mav
        self.store = store
        self.sysid = sysid
        self.compid = compid
        self.uploads: dict[int, _Upload] = {}
        self.current = 0
        self.on_change: Callable[[int], None] = lambda mission_type: None
        self.say: Callable[[str, int], None] = lambda text, severity: None  # STATUSTEXT
        # A refusal's text at most twice a second: a flood of bad uploads must not become a
        # flood of STATUSTEXT on the radio (each is still counted in ``refused``). The link
        # plug-in gives it the limiter its command refusals go through: one flood, one limit.
        self.refusal = RefusalTexts(
            lambda text: self.say(text, d.MAV_SEVERITY_WARNING), time.monotonic
        )
        # MISSION_SET_CURRENT's item for the commander (False: none runs, the link's own).
        self.ask_commander: Callable[[int], bool] = lambda seq: False
        self.jumps: int | None = None  # the commander's set-currents, when last seen
        self.news = False  # a set-current accepted: MISSION_CURRENT to every station
        self.running = False  # the flight controller flies the mission (MISSION_CURRENT's)
        # The stored mission was flown to its end: MISSION_CURRENT says so after the flight
        # controller stops (landed and disarmed), as PX4's does, until the mission changes.
        self.completed = False
        # Flown since it was stored and left before its end: MISSION_CURRENT keeps the item
        # it was at (PAUSED), as PX4 and ArduPilot do, where it had fallen back to item 0.
        self.paused = False
        self.refused = 0
        self.rejected_target = 0  # for another component of this system
        self.verdicts = PlanVerdicts()  # the pre-arm checks' view of the stored plans
        self.fence = self._fence()

    def _ack(self, peer: Peer, result: int, mission_type: int) -> Outgoing:
        msg = self.mav.mission_ack_encode(peer.sysid, peer.compid, result, mission_type)
        return Outgoing(msg, peer)

    def _request(self, upload: _Upload, now_s: float) -> Outgoing:
        upload.asked_at = now_s
        seq = len(upload.items)
        peer = upload.peer
        msg = self.mav.mission_request_int_encode(peer.sysid, peer.compid, seq, upload.mission_type)
        return Outgoing(msg, peer)

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        # Broadcasts count too: MAVProxy addresses sysid 0 until it has heard a heartbeat.
        if msg.target_system not in (0, self.sysid) or msg.target_component not in (0, self.compid):
            self.rejected_target += 1
            return []
        mission_type = getattr(msg, "mission_type", 0)
        if mission_type not in MISSION_TYPES:
            return [self._ack(peer, d.MAV_MISSION_UNSUPPORTED, mission_type)]
        kind = msg.get_type()
        if kind == "MISSION_COUNT":
            return self._start_upload(msg.count, mission_type, peer, now_s)
        if kind in ("MISSION_ITEM_INT", "MISSION_ITEM"):
            return self._item(msg, mission_type, peer, now_s)
        if kind == "MISSION_REQUEST_LIST":
            count = len(self.store.items[mission_type])
            return [
                Outgoing(
                    self.mav.mission_count_encode(peer.sysid, peer.compid, count, mission_type),
                    peer,
                )
            ]
        if kind in ("MISSION_REQUEST_INT", "MISSION_REQUEST"):
            return self._send_item(msg.seq, mission_type, peer, legacy=kind == "MISSION_REQUEST")
        if kind == "MISSION_CLEAR_ALL":
            self.store.replace(mission_type, [])
            self._changed(mission_type)
            return [self._ack(peer, d.MAV_MISSION_ACCEPTED, mission_type)]
        if kind == "MISSION_SET_CURRENT":
            return self._set_current(msg.seq, peer)
        return []  # MISSION_ACK closing a download: nothing to do

    def _start_upload(
        self, count: int, mission_type: int, peer: Peer, now_s: float
    ) -> list[Outgoing]:
        busy = self.uploads.get(mission_type)
        if busy is not None and busy.peer != peer:
            return [self._ack(peer, d.MAV_MISSION_DENIED, mission_type)]
        if count > MAX_ITEMS:
            self.refused += 1
            return [self._ack(peer, d.MAV_MISSION_NO_SPACE, mission_type)]
        if count == 0:
            self.uploads.pop(mission_type, None)
            self.store.replace(mission_type, [])
            self._changed(mission_type)
            return [self._ack(peer, d.MAV_MISSION_ACCEPTED, mission_type)]
        upload = self.uploads[mission_type] = _Upload(peer, mission_type, count)
        return [self._request(upload, now_s)]

    def _item(self, msg: Any, mission_type: int, peer: Peer, now_s: float) -> list[Outgoing]:
        upload = self.uploads.get(mission_type)
        if upload is None or upload.peer != peer:
            return []
        if msg.seq != len(upload.items):
            return [self._request(upload, now_s)]  # out of order or a duplicate: re-ask
        bad_xy = _bad_legacy_position(msg)
        if bad_xy is not None:  # MISSION_ITEM's float degrees: NaN or infinity
            del self.uploads[mission_type]
            self.refused += 1
            return [self._ack(peer, bad_xy, mission_type)]
        upload.items.append(MissionItem.from_message(msg))
        upload.retries = 0
        if len(upload.items) < upload.count:
            return [self._request(upload, now_s)]
        del self.uploads[mission_type]
        items = upload.items
        notes: list[str] = []
        if mission_type == d.MAV_MISSION_TYPE_FENCE:  # zones that enclose nothing: left out
            items, notes = honoured(items)
        elif (note := not_carried_note(items)) is not None:  # a gimbal's angles, say
            notes = [note]
        result, bad = first_refusal(items)
        if result == d.MAV_MISSION_ACCEPTED:
            self.store.replace(mission_type, items)
            self.current = 0 if mission_type == 0 else self.current
            self._changed(mission_type)
            for note in notes:
                log.warning("%s", note)
                self.say(note, d.MAV_SEVERITY_WARNING)
        else:
            self.refused += 1
            assert bad is not None  # a refusal is always an item's
            text = _refusal_text(result, bad)  # the ack's code alone names no item
            log.warning("%s", text)
            self.refusal(text)
        return [self._ack(peer, result, mission_type)]

    def _send_item(self, seq: int, mission_type: int, peer: Peer, legacy: bool) -> list[Outgoing]:
        items = self.store.items[mission_type]
        if not 0 <= seq < len(items):
            return [self._ack(peer, d.MAV_MISSION_INVALID_SEQUENCE, mission_type)]
        it = items[seq]
        current = int(mission_type == 0 and seq == self.current)
        common = (it.seq, it.frame, it.command, current, it.autocontinue)
        params = (it.param1, it.param2, it.param3, it.param4)
        if legacy:
            msg = self.mav.mission_item_encode(
                peer.sysid,
                peer.compid,
                *common,
                *params,
                it.x / 1e7,
                it.y / 1e7,
                it.z,
                mission_type,
            )
        else:
            msg = self.mav.mission_item_int_encode(
                peer.sysid, peer.compid, *common, *params, it.x, it.y, it.z, mission_type
            )
        return [Outgoing(msg, peer)]

    def set_current(self, seq: int) -> bool:
        """Make item ``seq`` the current one (MISSION_SET_CURRENT, DO_SET_MISSION_CURRENT);
        False, nothing changed, when the mission has no such item."""
        if not 0 <= seq < len(self.store.items[0]):
            return False
        self.current = seq
        self._changed(0)
        return True

    def _set_current(self, seq: int, peer: Peer) -> list[Outgoing]:
        if 0 <= seq < len(self.store.items[0]) and self.ask_commander(seq):
            return []  # MISSION_CURRENT once the commander accepts (``follow_status``)
        if self.set_current(seq):
            return [Outgoing(self.mission_current(), None)]  # news for every ground station
        # No such item: the unchanged item to the sender only, as a refused PARAM_SET is
        # answered; a flood of them on one link must not crowd telemetry off the others.
        self.refused += 1
        return [Outgoing(self.mission_current(), peer)]

    def follow(self, mission_state: int, seq: int = -1) -> None:
        """The flight controller's MissionState of the stored mission and its item, while
        it runs: the item it flies becomes the current one."""
        if mission_state == MissionState.ACTIVE and 0 <= seq < len(self.store.items[0]):
            self.current, self.paused = seq, True
        if mission_state != MissionState.NOT_STARTED:
            self.completed = mission_state == MissionState.COMPLETE
            self.paused = self.paused and not self.completed

    def follow_status(self, status: Any) -> None:
        """The commander's status: a set-current it accepted makes its item the current one
        (the count seen first, after a restart of either, is none)."""
        if status is None:
            return
        count, item = int(status.mission_jumps), int(status.mission_jump_to)
        if self.jumps is not None and count > self.jumps and 0 <= item < len(self.store.items[0]):
            self.current, self.completed, self.news = item, False, True
        self.jumps = count

    def _fence(self) -> Fence | None:
        items = self.store.items[d.MAV_MISSION_TYPE_FENCE]
        return Fence.from_items(items) if items else None

    def _changed(self, mission_type: int) -> None:
        if mission_type == 0:
            self.completed = self.paused = False
        if mission_type == d.MAV_MISSION_TYPE_FENCE:
            self.fence = self._fence()
        self.on_change(mission_type)

    def describe(self, s: Snapshot) -> None:
        """The stored plans as the telemetry tells of them (MISSION_CURRENT, SYS_STATUS)."""
        self.follow_status(s.status)
        self.running = s.control is not None and s.control.mission_state == MissionState.ACTIVE
        s.mission_seq, s.mission_total = self.current, len(self.store.items[0])
        s.mission_completed, s.mission_paused = self.completed, self.paused
        s.fence = self.fence

    def mission_current(self) -> Any:
        total = len(self.store.items[0])
        if total and (self.running or self.paused):  # flying it, or left before its end
            state = d.MISSION_STATE_ACTIVE if self.running else d.MISSION_STATE_PAUSED
            return self.mav.mission_current_encode(self.current, total, state)
        return mission_current_message(self.mav, self.current, total)

    def next_due(self) -> float:
        """When an upload's item is next asked for again."""
        return min((u.asked_at + ITEM_TIMEOUT_S for u in self.uploads.values()), default=math.inf)

    def tick(self, now_s: float) -> list[Outgoing]:
        out: list[Outgoing] = []
        if self.news:
            out.append(Outgoing(self.mission_current(), None))
            self.news = False
        for mission_type, upload in list(self.uploads.items()):
            if now_s - upload.asked_at < ITEM_TIMEOUT_S:
                continue
            if upload.retries >= MAX_RETRIES:
                del self.uploads[mission_type]
                log.warning("mission upload timed out at item %d", len(upload.items))
                out.append(self._ack(upload.peer, d.MAV_MISSION_OPERATION_CANCELLED, mission_type))
                continue
            upload.retries += 1
            out.append(self._request(upload, now_s))
        return out


def _bad_legacy_position(msg: Any) -> int | None:
    """INVALID_PARAM5_X/6_Y for a MISSION_ITEM whose degrees cannot become integers."""
    if msg.get_type() != "MISSION_ITEM":
        return None
    if not math.isfinite(msg.x) or abs(msg.x) > 1e3:
        return d.MAV_MISSION_INVALID_PARAM5_X
    if not math.isfinite(msg.y) or abs(msg.y) > 1e3:
        return d.MAV_MISSION_INVALID_PARAM6_Y
    return None


_WHY = {
    d.MAV_MISSION_UNSUPPORTED: "a command this vehicle does not fly",
    d.MAV_MISSION_UNSUPPORTED_FRAME: "a frame this vehicle does not take",
    d.MAV_MISSION_INVALID_PARAM5_X: "latitude out of range",
    d.MAV_MISSION_INVALID_PARAM6_Y: "longitude out of range",
    d.MAV_MISSION_INVALID_PARAM7: "altitude out of range",
    TAKEOFF_NOT_FIRST: "a take-off after an item to fly to; an ArduPilot .waypoints file's"
    " line 0 is home: delete it",
}


def _refusal_text(result: int, item: MissionItem) -> str:
    """What a ground station is told of a refused upload: the item, its command, why."""
    name = d.enums["MAV_MISSION_RESULT"][result].name
    why = _WHY.get(result) or name.removeprefix("MAV_MISSION_").lower().replace("_", " ")
    if item.command == d.MAV_CMD_NAV_DELAY and result == d.MAV_MISSION_INVALID_PARAM1:
        why = "seconds to wait, not a time of day"
    return f"Mission refused: item {item.seq} ({command_name(item.command)}): {why}"
