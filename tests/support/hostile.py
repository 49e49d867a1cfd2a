"""A hostile ground station's byte stream, reproducible from a seed.

Four kinds of frame, mixed: random bytes; valid frames with one byte changed (a CRC-16
always catches a one-byte change, so none of them can act); valid frames cut short; and
valid, well-addressed frames whose values break a rule (NaN, infinity, out of range) in
every message the vehicle accepts. None of them may change the vehicle: commands that
could (arming, mode changes, reboot) always carry at least one value their rule refuses,
missions are never cleared or completed, and parameters only get values they refuse.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from dataclasses import dataclass, field

from companion.link.command_rules import RULES, Param
from companion.link.command_service import SET_MODE_MESSAGE
from mavlink_dialect import companion as d

BAD_FLOATS = (math.nan, math.inf, -math.inf, 3.4e38, -3.4e38)
# A parameter name that exists, with values every declaration refuses.
PARAM_NAMES = ("SR_ATTITUDE", "SR_POSITION", "SYS_FAILURE_EN", "NOT_A_PARAM", "")
CHECKED_COMMANDS = sorted(c for c, rules in RULES.items() if rules and c != SET_MODE_MESSAGE)


@dataclass
class HostileFrame:
    data: bytes
    kind: str  # random, mutated, truncated, hostile
    command: int | None = None  # a command that must be answered by one COMMAND_ACK


@dataclass
class HostileStream:
    """Frames addressed to vehicle ``sysid`` from ground station (255, 190)."""

    seed: int = 1
    sysid: int = 1
    rng: random.Random = field(init=False)

    def __post_init__(self) -> None:
        self.rng = random.Random(self.seed)
        self.mav = d.MAVLink(None, srcSystem=255, srcComponent=190)
        self.builders: list[Callable[[], tuple[object, int | None]]] = [
            self._command_long,
            self._command_int,
            self._param_set,
            self._mission_item,
            self._mission_count,
            self._small_requests,
        ]

    def frame(self) -> HostileFrame:
        roll = self.rng.random()
        if roll < 0.15:
            return HostileFrame(self.rng.randbytes(self.rng.randint(1, 280)), "random")
        msg, command = self.rng.choice(self.builders)()
        packed = bytearray(msg.pack(self.mav))  # type: ignore[attr-defined]
        if roll < 0.35:
            i = self.rng.randrange(1, len(packed))
            packed[i] ^= self.rng.randint(1, 255)
            return HostileFrame(bytes(packed), "mutated")
        if roll < 0.45:
            return HostileFrame(bytes(packed[: self.rng.randrange(1, len(packed))]), "truncated")
        return HostileFrame(bytes(packed), "hostile", command)

    def _bad(self) -> float:
        return self.rng.choice(BAD_FLOATS)

    def _any(self) -> float:
        return self.rng.choice((0.0, 1.0, -1.0, self.rng.uniform(-1e6, 1e6), *BAD_FLOATS))

    def _breaking(self, rule: Param) -> float:
        """A value ``rule`` refuses."""
        choices = [math.inf, -math.inf, rule.hi + 1 + abs(rule.hi), rule.lo - 1 - abs(rule.lo)]
        if not rule.optional:
            choices.append(math.nan)
        return self.rng.choice(choices)

    def _command_params(self) -> tuple[int, list[float], int]:
        """A checked command, its parameters, and the 1-based index of the broken one."""
        command = self.rng.choice(CHECKED_COMMANDS)
        params = [self._any() for _ in range(7)]
        rule = self.rng.choice(RULES[command])
        params[rule.index - 1] = self._breaking(rule)
        return command, params, rule.index

    def _command_long(self) -> tuple[object, int | None]:
        command, params, _ = self._command_params()
        return self.mav.command_long_encode(self.sysid, 1, command, 0, *params), command

    def _off_the_earth(self, limit_deg: float) -> int:
        """An int32 of degrees × 1e7 beyond ``limit_deg``."""
        return self.rng.choice((-1, 1)) * self.rng.randint(round(limit_deg * 1e7) + 1, 2**31 - 1)

    def _command_int(self) -> tuple[object, int | None]:
        command, p, broken = self._command_params()
        x = self.rng.randint(-(2**31), 2**31 - 1)
        y = self.rng.randint(-(2**31), 2**31 - 1)
        if broken == 5:  # COMMAND_INT carries latitude and longitude as x and y
            x = self._off_the_earth(90)
        elif broken == 6:
            y = self._off_the_earth(180)
        frame = self.rng.randint(0, 21)
        msg = self.mav.command_int_encode(self.sysid, 1, frame, command, 0, 0, *p[:4], x, y, p[6])
        return msg, command

    def _param_set(self) -> tuple[object, int | None]:
        name = self.rng.choice(PARAM_NAMES).encode()
        return self.mav.param_set_encode(self.sysid, 1, name, self._bad(), 9), None

    def _mission_item(self) -> tuple[object, int | None]:
        # An item no upload asked for, or one that breaks the upload: never stored.
        seq = self.rng.randint(0, 65535)
        cmd = self.rng.choice((d.MAV_CMD_NAV_WAYPOINT, d.MAV_CMD_DO_JUMP, d.MAV_CMD_NAV_LAND))
        p = [self._bad(), self._any(), self._any(), self._bad()]
        x, y = self.rng.randint(-(2**31), 2**31 - 1), self.rng.randint(-(2**31), 2**31 - 1)
        msg = self.mav.mission_item_int_encode(
            self.sysid, 1, seq, 6, cmd, 0, 1, *p, x, y, self._bad(), 0
        )
        return msg, None

    def _mission_count(self) -> tuple[object, int | None]:
        # Starts an upload that hostile items then break (or that times out): never count 0,
        # which is a valid request to clear the mission.
        mission_type = self.rng.choice((0, 1, 2, 7, 255))
        count = self.rng.randint(1, 65535)
        return self.mav.mission_count_encode(self.sysid, 1, count, mission_type), None

    def _small_requests(self) -> tuple[object, int | None]:
        pick = self.rng.randrange(4)
        if pick == 0:
            return self.mav.timesync_encode(self.rng.randint(-(2**63), 2**63 - 1), 0), None
        if pick == 1:
            index = self.rng.randint(-32768, 32767)
            return self.mav.param_request_read_encode(self.sysid, 1, b"", index), None
        if pick == 2:
            seq = self.rng.randint(0, 65535)
            return self.mav.mission_request_int_encode(self.sysid, 1, seq, 0), None
        return self.mav.heartbeat_encode(6, 8, self.rng.randint(0, 255), 0, 4), None
