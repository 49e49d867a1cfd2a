"""A hostile ground station's byte stream, reproducible from a seed.

Four kinds of frame, mixed: random bytes; valid frames with one byte changed (a CRC-16
always catches a one-byte change, so none of them can act); valid frames cut short; and
valid, well-addressed frames whose values break a rule (NaN, infinity, out of range) in
every message the vehicle accepts (HOSTILE_TYPES). None of them may change the vehicle:
commands that could (arming, mode changes, reboot) always carry at least one value their
rule refuses, as does the old SET_MODE message; missions are never cleared (no
MISSION_CLEAR_ALL, no MISSION_COUNT of 0) or completed, MISSION_SET_CURRENT names no item
of theirs, parameters only get values they refuse, log data is asked beyond every log's end
and never erased (no LOG_ERASE), and the joystick's axes are out of range. Requests that
only read go to this component, to every one (0) or to another (counted as refused).
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from dataclasses import dataclass, field

from companion.control.modes import decode_set_mode
from companion.link.command_rules import RULES, Param
from companion.link.command_service import SET_MODE_MESSAGE
from mavlink_dialect import companion as d

BAD_FLOATS = (math.nan, math.inf, -math.inf, 3.4e38, -3.4e38)
# A parameter name that exists, with values every declaration refuses.
PARAM_NAMES = ("SR_ATTITUDE", "SR_POSITION", "SYS_FAILURE_EN", "NOT_A_PARAM", "")
CHECKED_COMMANDS = sorted(c for c, rules in RULES.items() if rules and c != SET_MODE_MESSAGE)
# Every message type the link accepts except LOG_ERASE and MISSION_CLEAR_ALL, which change
# the vehicle by design (tests check this list against the link's services).
HOSTILE_TYPES = frozenset(
    {
        "COMMAND_LONG", "COMMAND_INT", "SET_MODE", "PARAM_SET", "PARAM_REQUEST_LIST",
        "PARAM_REQUEST_READ", "MISSION_COUNT", "MISSION_ITEM_INT", "MISSION_ITEM",
        "MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_REQUEST_LIST", "MISSION_SET_CURRENT",
        "MISSION_ACK", "TIMESYNC", "HEARTBEAT", "MANUAL_CONTROL", "FILE_TRANSFER_PROTOCOL",
        "LOG_REQUEST_LIST", "LOG_REQUEST_DATA", "LOG_REQUEST_END",
    }
)  # fmt: skip
FTP_OPCODES = (0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 128, 129, 255)
AXIS_LIMIT = 1000  # MANUAL_CONTROL's x, y, r: beyond ±1000 (and not 32767, "unused") refused


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
            self._mission_requests,
            self._set_mode,
            self._manual_control,
            self._ftp,
            self._log_requests,
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
        if self.rng.random() < 0.3:  # the old MISSION_ITEM, degrees as floats
            lat, lon = self._any(), self._any()
            z = self._bad()
            msg = self.mav.mission_item_encode(self.sysid, 1, seq, 3, cmd, 0, 1, *p, lat, lon, z)
            return msg, None
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

    def _component(self) -> int:
        """This component mostly; every component (0) or another one now and then."""
        return self.rng.choice((1, 1, 1, 0, self.rng.randint(2, 255)))

    def _small_requests(self) -> tuple[object, int | None]:
        pick, comp = self.rng.randrange(5), self._component()
        if pick == 0:  # a request (tc1 0) or somebody's reply, to anyone
            tc1 = self.rng.choice((0, self.rng.randint(-(2**63), 2**63 - 1)))
            ts1 = self.rng.randint(-(2**63), 2**63 - 1)
            return self.mav.timesync_encode(tc1, ts1, self.sysid, comp), None
        if pick == 1:
            index = self.rng.randint(-32768, 32767)
            name = self.rng.choice(PARAM_NAMES).encode()
            return self.mav.param_request_read_encode(self.sysid, comp, name, index), None
        if pick == 2 and self.rng.random() < 0.1:  # the whole list: rarely, it is long
            return self.mav.param_request_list_encode(self.sysid, comp), None
        if pick == 2:
            return self.mav.heartbeat_encode(6, 8, self.rng.randint(0, 255), 0, 4), None
        seq = self.rng.randint(0, 65535)
        if pick == 3:
            return self.mav.mission_request_int_encode(self.sysid, comp, seq, 0), None
        return self.mav.mission_request_encode(self.sysid, comp, seq, 0), None

    def _mission_requests(self) -> tuple[object, int | None]:
        pick, comp = self.rng.randrange(3), self._component()
        mission_type = self.rng.choice((0, 1, 2, 7, 255))
        if pick == 0:
            return self.mav.mission_request_list_encode(self.sysid, comp, mission_type), None
        if pick == 1:  # no mission here has this many items: the current one stays
            seq = self.rng.randint(1000, 65535)
            return self.mav.mission_set_current_encode(self.sysid, comp, seq), None
        result = self.rng.randint(0, 255)
        return self.mav.mission_ack_encode(self.sysid, comp, result, mission_type), None

    def _set_mode(self) -> tuple[object, int | None]:
        """The old SET_MODE message with a mode no encoding names (answered DENIED)."""
        while True:
            base, custom = self.rng.randint(0, 255), self.rng.randint(0, 2**32 - 1)
            if decode_set_mode(base, custom) is None:
                msg = self.mav.set_mode_encode(self.sysid, base, custom)
                return msg, SET_MODE_MESSAGE

    def _axis_out_of_range(self) -> int:
        return self.rng.choice((-1, 1)) * self.rng.randint(AXIS_LIMIT + 1, 32766)

    def _manual_control(self) -> tuple[object, int | None]:
        """The joystick with at least one axis out of range (refused, never flown)."""
        axes = [self.rng.randint(-32768, 32767) for _ in range(4)]  # x, y, z, r
        axes[self.rng.choice((0, 1, 3))] = self._axis_out_of_range()
        buttons = self.rng.randint(0, 65535)
        return self.mav.manual_control_encode(self.sysid, *axes, buttons), None

    def _ftp(self) -> tuple[object, int | None]:
        """A FILE_TRANSFER_PROTOCOL payload: random, or a real opcode with random fields
        (the server is read-only)."""
        payload = bytearray(self.rng.randbytes(251))
        if self.rng.random() < 0.7:
            payload[3] = self.rng.choice(FTP_OPCODES)
            payload[4] = self.rng.choice((0, 1, 239, 240, 255))  # data size
        network = self.rng.choice((0, 0, 0, self.rng.randint(1, 255)))
        comp = self._component()
        return self.mav.file_transfer_protocol_encode(network, self.sysid, comp, payload), None

    def _log_requests(self) -> tuple[object, int | None]:
        pick, comp = self.rng.randrange(3), self._component()
        if pick == 0:
            start, end = self.rng.randint(0, 65535), self.rng.randint(0, 65535)
            return self.mav.log_request_list_encode(self.sysid, comp, start, end), None
        if pick == 1:  # beyond the end of any log (or none at all): refused, nothing sent
            log_id = self.rng.randint(0, 65535)
            ofs, count = self.rng.randint(2**31, 2**32 - 1), self.rng.randint(0, 2**32 - 1)
            return self.mav.log_request_data_encode(self.sysid, comp, log_id, ofs, count), None
        return self.mav.log_request_end_encode(self.sysid, comp), None
