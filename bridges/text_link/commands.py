"""START and STOP from the old ground station, as MAVLink commands with retries and acks.

``START`` arms (MAV_CMD_COMPONENT_ARM_DISARM, param1 1) and, when asked, starts the
mission once the arm is accepted; ``STOP`` disarms (param1 0; param2 21196 only when the
bridge is told to force it, because the vehicle refuses a plain disarm in the air). A
command without an answer is sent again with the confirmation counted up, as QGroundControl
and MAVSDK do, so the vehicle can tell a retransmission from a new command. A new word
from the ground station replaces one still waiting: the latest order wins.
"""

from __future__ import annotations

import logging
from collections import deque
from dataclasses import dataclass

from mavlink_dialect import companion as mavlink

log = logging.getLogger(__name__)

FORCE_DISARM = 21196.0
IN_PROGRESS_WAIT_S = 10.0  # after IN_PROGRESS, how long the final answer may take
RESULT_NAMES = {value: entry.name for value, entry in mavlink.enums["MAV_RESULT"].items()}


@dataclass
class CommandLong:
    """One COMMAND_LONG to send (the target is filled in by the caller)."""

    command: int
    params: tuple[float, ...]
    confirmation: int


@dataclass
class _Pending:
    word: str  # what the ground station sent
    label: str  # what the log calls this command
    command: int
    params: tuple[float, ...]
    sends: int = 0
    next_send_s: float = 0.0
    in_progress: bool = False


@dataclass
class CommandOutcome:
    """How a word from the ground station ended, for the log and the tests."""

    word: str
    label: str
    result: str  # a MAV_RESULT name, or "NO_ACK"


class CommandSender:
    """One command in flight at a time; ``tick`` says what to (re)send."""

    def __init__(
        self,
        start_mission: bool = False,
        force_stop: bool = False,
        retry_s: float = 1.0,
        attempts: int = 4,
    ) -> None:
        self.start_mission = start_mission
        self.force_stop = force_stop
        self.retry_s = retry_s
        self.attempts = attempts
        self.pending: _Pending | None = None
        self.outcomes: deque[CommandOutcome] = deque(maxlen=100)  # the latest, for status

    def request(self, word: str, now_s: float) -> None:
        """The ground station sent ``word`` (START or STOP)."""
        if word == "START":
            new = self._arm(word, 1.0, 0.0, "arm")
        elif word == "STOP":
            force = FORCE_DISARM if self.force_stop else 0.0
            new = self._arm(word, 0.0, force, "forced disarm" if force else "disarm")
        else:
            raise ValueError(f"not a command: {word!r}")
        if self.pending is not None:
            self._finish("SUPERSEDED")
        new.next_send_s = now_s
        self.pending = new

    def tick(self, now_s: float) -> CommandLong | None:
        """The command to send now, if one is due."""
        p = self.pending
        if p is None or now_s < p.next_send_s:
            return None
        if p.in_progress:  # the vehicle is working on it: wait for the final answer, bounded
            self._finish("NO_FINAL_ACK")
            return None
        if p.sends >= self.attempts:
            self._finish("NO_ACK")
            return None
        p.sends += 1
        p.next_send_s = now_s + self.retry_s
        return CommandLong(p.command, p.params, confirmation=p.sends - 1)

    def on_ack(self, command: int, result: int, now_s: float) -> None:
        """A COMMAND_ACK from the vehicle."""
        p = self.pending
        if p is None or command != p.command:
            return
        if result == mavlink.MAV_RESULT_IN_PROGRESS:
            p.in_progress = True
            p.next_send_s = now_s + IN_PROGRESS_WAIT_S
            return
        name = RESULT_NAMES.get(result, str(result))
        armed = p.label == "arm" and result == mavlink.MAV_RESULT_ACCEPTED
        self._finish(name)
        if armed and self.start_mission:
            self.pending = _Pending(p.word, "mission start", mavlink.MAV_CMD_MISSION_START, (0, 0))
            self.pending.next_send_s = now_s

    def _arm(self, word: str, arm: float, force: float, label: str) -> _Pending:
        return _Pending(word, label, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, (arm, force))

    def _finish(self, result: str) -> None:
        p = self.pending
        assert p is not None
        self.pending = None
        self.outcomes.append(CommandOutcome(p.word, p.label, result))
        level = logging.INFO if result == "MAV_RESULT_ACCEPTED" else logging.WARNING
        log.log(level, "%s: %s -> %s", p.word, p.label, result)
