"""The parameter microservice: list, read by name or index, set with echo.

A full list is streamed a few PARAM_VALUEs per tick so a slow radio is not flooded;
``param_count`` and indexes are fixed (0..count-1) so QGroundControl can re-read gaps.
A set of an alias (``companion.params.alias``) changes the parameters it stands for; the
new values of both are sent, so a ground station's copy of either is never stale.
"""

from __future__ import annotations

import logging
import math
from collections import deque
from collections.abc import Callable
from typing import Any

from companion.link.microservice import Outgoing, Peer
from companion.params.live import RELOAD_ALL
from companion.params.store import ParamError, ParamStore

log = logging.getLogger(__name__)
REAL32 = 9
PER_TICK = 25
PACE_S = 0.05  # PER_TICK values this often while a list or a change waits to go out


def _name(raw: Any) -> str:
    if isinstance(raw, bytes):
        raw = raw.decode(errors="replace")
    return str(raw).split("\0", 1)[0]


class ParamsService:
    """Serves a ParamStore to ground stations."""

    handles = frozenset({"PARAM_REQUEST_LIST", "PARAM_REQUEST_READ", "PARAM_SET"})

    def __init__(
        self,
        mav: Any,
        store: ParamStore,
        sysid: int,
        compid: int = 1,
        on_refusal: Callable[[str], None] | None = None,
    ) -> None:
        self.mav = mav
        self.store = store
        self.sysid = sysid
        self.compid = compid
        self.on_refusal = on_refusal or (lambda text: None)
        self.on_change: Callable[[str, float], None] = lambda name, value: None
        self._queue: deque[tuple[int, Peer | None]] = deque()
        self._sent_at_s = -math.inf
        self.refused = 0
        # Names whose write is an action, not a value to keep: the action runs (ParamError
        # when it cannot now) and the parameter still reads its stored value.
        self.actions: dict[str, Callable[[float], None]] = {}
        self.rejected_target = 0  # for another component of this system

    def _for_us(self, msg: Any) -> bool:
        targets = (0, self.sysid)  # broadcasts included, as for missions
        return msg.target_system in targets and msg.target_component in (0, self.compid)

    def value(self, index: int) -> Any:
        name = self.store.names[index]
        return self.mav.param_value_encode(
            name.encode(), self.store.get(name), REAL32, len(self.store), index
        )

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        if not self._for_us(msg):
            self.rejected_target += 1
            return []
        kind = msg.get_type()
        if kind == "PARAM_REQUEST_LIST":
            # A station asking again restarts its own list; another station's list and the
            # values queued for everyone go on (ArduPilot keeps a list per link): QGC and
            # MAVProxy connecting together each get every index.
            self._queue = deque(entry for entry in self._queue if entry[1] != peer)
            self._queue.extend((i, peer) for i in range(len(self.store)))
            return self.tick(now_s)
        if kind == "PARAM_REQUEST_READ":
            return self._read(msg, peer)
        return self._set(msg, peer)

    def _read(self, msg: Any, peer: Peer) -> list[Outgoing]:
        index = msg.param_index
        if index < 0:
            name = _name(msg.param_id)
            if name not in self.store.decls:
                return []
            index = self.store.index_of(name)
        if index >= len(self.store):
            return []
        return [Outgoing(self.value(index), peer)]

    def _set(self, msg: Any, peer: Peer) -> list[Outgoing]:
        name = _name(msg.param_id)
        if name not in self.store.decls:
            self.refused += 1
            self.on_refusal(f"Unknown parameter {name}")
            return []
        try:
            return self.write(name, msg.param_value)
        except ParamError as exc:
            self.refused += 1
            self.on_refusal(f"Param refused: {exc}")
            # The old value, to the sender only: nothing changed for anyone else, and a
            # flood of bad writes on one link must not be repeated on every other one.
            return [Outgoing(self.value(self.store.index_of(name)), peer)]

    def write(self, name: str, value: float) -> list[Outgoing]:
        """Set a parameter (from a ground station, or a calibration's result); ParamError
        when refused, nothing changed."""
        action = self.actions.get(name)
        if action is not None:
            self.store.plan(name, value)  # its range and values: ParamError
            action(value)
            return [Outgoing(self.value(self.store.index_of(name)), None)]
        changed = self.store.write(name, value)
        for own, new in changed.items():  # an alias's owners follow their own names
            self.on_change(own, new)
        # A change is news for every ground station: the name set first (the sender waits
        # for it), then every name that reads the same value (an alias and its owner).
        names = [name, *self.store.linked(name)]
        return [Outgoing(self.value(self.store.index_of(n)), None) for n in names]

    def reset(self) -> list[str]:
        """Every parameter back to its default (MAV_CMD_PREFLIGHT_STORAGE); the stored ones
        whose value changed. Their owners read the stored values again; every ground station
        gets each new value, and its aliases', a few per tick."""
        changed = sorted(self.store.reset())
        if not changed:
            return []
        self.on_change(RELOAD_ALL, 0.0)
        names = sorted({n for own in changed for n in (own, *self.store.linked(own))})
        self._queue.extend((self.store.index_of(name), None) for name in names)
        return changed

    def next_due(self) -> float:
        """When the next values should go out (the link sleeps until then)."""
        return self._sent_at_s + PACE_S if self._queue else math.inf

    def tick(self, now_s: float) -> list[Outgoing]:
        out = []
        if self._queue:
            self._sent_at_s = now_s
        for _ in range(min(PER_TICK, len(self._queue))):
            index, peer = self._queue.popleft()
            out.append(Outgoing(self.value(index), peer))
        return out
