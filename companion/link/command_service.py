"""The command microservice: COMMAND_LONG and COMMAND_INT in, exactly one COMMAND_ACK out.

Handlers are registered per MAV_CMD. A handler answers at once, or defers: the command
went onto the bus for another plug-in and the ack follows when that plug-in answers (or
FAILED when nobody does in time). Unknown commands get UNSUPPORTED at once, and a
retransmission is never executed twice: one with confirmation > 0, and the same command
with the same parameters from the same sender while the first is still in progress
(MAVSDK resends an unanswered command every 0.5 s with confirmation 0). A retransmission
of a command in progress gets no answer of its own: the first's final ack answers both
(MAVSDK's Gripper plug-in, among others, takes an IN_PROGRESS for the final result).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Collection
from dataclasses import dataclass, field
from typing import Any

from companion.link.codec import dialect as d
from companion.link.microservice import Outgoing, Peer

log = logging.getLogger(__name__)

RETRY_MEMORY_S = 10.0  # how long a finished command's result is kept for retransmissions
SET_MODE_MESSAGE = 11  # the SET_MODE message's id, used as its command number


INT32_MAX = 2**31 - 1


@dataclass(frozen=True)
class CommandArgs:
    """A decoded command, the same for COMMAND_LONG and COMMAND_INT."""

    command: int
    params: tuple[float, ...]  # param1..param7 (x, y as degrees for COMMAND_INT)
    confirmation: int
    peer: Peer
    is_int: bool = False
    frame: int = 0  # COMMAND_INT's frame (MAV_FRAME_GLOBAL for COMMAND_LONG)


@dataclass
class Outcome:
    """What a handler decided: a final result, or a deferral keyed by a bus sequence."""

    result: int = d.MAV_RESULT_ACCEPTED
    # Messages to send after the ack: to the sender, or as an Outgoing to whom it names
    # (None: every ground station, for news such as a new MISSION_CURRENT or PARAM_VALUE).
    extra: list[Any] = field(default_factory=list)
    defer_seq: int | None = None
    timeout_s: float = 3.0


Handler = Callable[[CommandArgs], Outcome]
Check = Callable[[CommandArgs], "str | None"]  # why a command is refused, or None


@dataclass
class _Pending:
    args: CommandArgs
    deadline: float


class CommandService:
    """Dispatches commands to handlers and answers each one exactly once."""

    handles = frozenset({"COMMAND_LONG", "COMMAND_INT", "SET_MODE"})

    def __init__(self, mav: Any, sysid: int, compid: int = 1) -> None:
        self.mav = mav
        self.sysid = sysid
        self.compid = compid
        self.handlers: dict[int, Handler] = {}
        self.pending: dict[int, _Pending] = {}
        self._done: dict[tuple[int, int, int], tuple[float, int | None]] = {}
        self.rejected_target = 0
        self.refused = 0  # commands whose parameters broke their rule (answered DENIED)
        self.handler_errors = 0  # handlers that raised: bugs, which the tests look for
        self.check: Check | None = None
        self.ruled: Collection[int] | None = None  # the commands ``check`` has a rule for
        self.on_refusal: Callable[[str], None] = lambda text: None

    def guard(self, check: Check, ruled: Collection[int]) -> None:
        """Check every command's parameters before its handler runs; from now on only a
        command ``check`` has a rule for (``ruled``) may be registered."""
        unruled = sorted(set(self.handlers) - set(ruled))
        if unruled:
            raise KeyError(f"no parameter rule for {', '.join(map(command_name, unruled))}")
        self.check, self.ruled = check, ruled

    def register(self, command: int, handler: Handler) -> None:
        """Answer ``command`` with ``handler``; KeyError when the service is guarded and the
        command has no parameter rule (its parameters would reach the handler unchecked)."""
        if self.ruled is not None and command not in self.ruled:
            raise KeyError(
                f"{command_name(command)}: no parameter rule (companion/link/command_rules.py)"
            )
        self.handlers[command] = handler

    def _args(self, msg: Any, peer: Peer) -> CommandArgs:
        if msg.get_type() == "COMMAND_INT":
            params = (
                msg.param1,
                msg.param2,
                msg.param3,
                msg.param4,
                _degrees(msg.x),
                _degrees(msg.y),
                msg.z,
            )
            return CommandArgs(msg.command, params, 0, peer, True, msg.frame)
        params = (
            msg.param1,
            msg.param2,
            msg.param3,
            msg.param4,
            msg.param5,
            msg.param6,
            msg.param7,
        )
        return CommandArgs(msg.command, params, msg.confirmation, peer)

    def ack(self, args: CommandArgs, result: int, progress: int = 0) -> Outgoing:
        msg = self.mav.command_ack_encode(
            args.command, result, progress, 0, args.peer.sysid, args.peer.compid
        )
        return Outgoing(msg, args.peer)

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        if msg.get_type() == "SET_MODE":
            # The old SET_MODE message: answered, as ArduPilot does, by a COMMAND_ACK whose
            # command is the message id (11).
            if msg.target_system not in (0, self.sysid):
                self.rejected_target += 1
                return []
            params = (float(msg.base_mode), float(msg.custom_mode), 0.0, 0.0, 0.0, 0.0, 0.0)
            return self.dispatch(CommandArgs(SET_MODE_MESSAGE, params, 0, peer), now_s)
        if msg.target_system not in (0, self.sysid) or msg.target_component not in (0, self.compid):
            self.rejected_target += 1
            return []
        return self.dispatch(self._args(msg, peer), now_s)

    def dispatch(self, args: CommandArgs, now_s: float) -> list[Outgoing]:
        """Run a decoded command through its handler; exactly one ack, retries remembered."""
        peer = args.peer
        key = (peer.sysid, peer.compid, args.command)
        previous = self._done.get(key)
        if previous and previous[1] is None and self._in_progress(args):
            return []  # a resend of a command in progress: its final ack is on its way
        if args.confirmation > 0 and previous and now_s - previous[0] < RETRY_MEMORY_S:
            result = previous[1]
            if result is not None:  # a retransmission: answered again, never acted twice
                return [self.ack(args, result)]
        handler = self.handlers.get(args.command)
        if handler is None:
            self._done[key] = (now_s, d.MAV_RESULT_UNSUPPORTED)
            return [self.ack(args, d.MAV_RESULT_UNSUPPORTED)]
        outcome = self._run(handler, args)
        if outcome.defer_seq is not None:
            self.pending[outcome.defer_seq] = _Pending(args, now_s + outcome.timeout_s)
            self._done[key] = (now_s, None)
            return []
        self._done[key] = (now_s, outcome.result)
        extra = [m if isinstance(m, Outgoing) else Outgoing(m, peer) for m in outcome.extra]
        return [self.ack(args, outcome.result), *extra]

    def _in_progress(self, args: CommandArgs) -> bool:
        """Whether ``args`` resends a command still in progress (a confirmation > 0, or
        the same parameters, NaN matching NaN)."""
        for pending in self.pending.values():
            first = pending.args
            if first.peer == args.peer and first.command == args.command:
                return args.confirmation > 0 or all(
                    a == b or (math.isnan(a) and math.isnan(b))
                    for a, b in zip(first.params, args.params, strict=True)
                )
        return False

    def _run(self, handler: Handler, args: CommandArgs) -> Outcome:
        reason = self.check(args) if self.check is not None else None
        if reason is not None:
            self.refused += 1
            self.on_refusal(f"{command_name(args.command)}: {reason}")
            return Outcome(d.MAV_RESULT_DENIED)
        try:
            return handler(args)
        except Exception:  # a handler bug must not take the link down
            self.handler_errors += 1
            log.exception("command %d handler failed", args.command)
            return Outcome(d.MAV_RESULT_FAILED)

    def complete(self, seq: int, result: int, now_s: float) -> list[Outgoing]:
        """The bus answered a deferred command: send its final ack."""
        pending = self.pending.pop(seq, None)
        if pending is None:
            return []
        args = pending.args
        self._done[(args.peer.sysid, args.peer.compid, args.command)] = (now_s, result)
        return [self.ack(args, result)]

    def next_due(self) -> float:
        """When a command forwarded to the vehicle is failed for want of an answer."""
        return min((p.deadline for p in self.pending.values()), default=math.inf)

    def tick(self, now_s: float) -> list[Outgoing]:
        out = []
        for seq, pending in list(self.pending.items()):
            if now_s >= pending.deadline:
                log.warning("command %d: no answer from the vehicle in time", pending.args.command)
                out += self.complete(seq, d.MAV_RESULT_FAILED, now_s)
        stale = [k for k, (t, _) in self._done.items() if now_s - t > RETRY_MEMORY_S]
        for k in stale:
            del self._done[k]
        return out


def command_name(command: int) -> str:
    """MAV_CMD_DO_REPOSITION -> DO_REPOSITION (SET_MODE for the message's number)."""
    if command == SET_MODE_MESSAGE:
        return "SET_MODE"
    entry = d.enums["MAV_CMD"].get(command)
    return entry.name.removeprefix("MAV_CMD_") if entry is not None else f"command {command}"


def _degrees(e7: int) -> float:
    """COMMAND_INT's x/y in degrees; INT32_MAX is the spec's "not given" (NaN here)."""
    return math.nan if e7 == INT32_MAX else e7 / 1e7
