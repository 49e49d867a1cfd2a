"""The MAVLink shell: SERIAL_CONTROL to the SHELL device, as PX4's nsh answers it.

QGroundControl's Analyze Tools → MAVLink Console sends each line typed, newline included,
with the flags RESPOND, EXCLUSIVE and MULTI, and an empty message without RESPOND when it
closes; PX4's ``mavlink_shell.py`` sends keystrokes as they come. Both show what comes back
(SERIAL_CONTROL with REPLY) as a terminal would: so the shell echoes what it is sent, then
the command's output (``shell_commands``) and its prompt, in pieces of the message's 70
bytes. Another device, a reply sent to the vehicle, a line past ``MAX_LINE`` characters or
bytes that are not text are refused and counted, never raised.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from companion.link.microservice import Outgoing, Peer
from companion.link.shell_commands import ShellFacts, run_command
from companion.messages import SystemHealth
from companion.params.store import ParamStore
from mavlink_dialect import companion as d

PROMPT = "companion> "
CHUNK = 70  # SERIAL_CONTROL's data field
MAX_LINE = 200  # characters of one command line
_ERASE = {0x08, 0x7F}  # backspace, delete: as a terminal sends them


class ShellService:
    """Answers QGroundControl's MAVLink Console."""

    handles = frozenset({"SERIAL_CONTROL"})

    def __init__(
        self, mav: Any, health: Callable[[], SystemHealth | None], params: ParamStore
    ) -> None:
        self.mav = mav
        self.facts = ShellFacts(health, params)
        self.line = ""  # typed, not yet ended by a newline
        self.open = False  # a console has spoken since it last closed
        self.refused = 0

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        if msg.device != d.SERIAL_CONTROL_DEV_SHELL or msg.flags & d.SERIAL_CONTROL_FLAG_REPLY:
            self.refused += 1  # a port this vehicle does not hand out, or a stray reply
            return []
        if not msg.flags & d.SERIAL_CONTROL_FLAG_RESPOND:
            self.line, self.open = "", False  # the console closed
            return []
        data = bytes(msg.data[: min(int(msg.count), CHUNK)])
        text = "" if self.open else PROMPT  # the first line a console sees starts at one
        self.open = True
        for byte in data:
            text += self._key(byte)
        return [Outgoing(self._reply(part), peer) for part in _pieces(text.encode())]

    def tick(self, now_s: float) -> list[Outgoing]:
        return []

    def _key(self, byte: int) -> str:
        """What one byte typed shows (its echo, and a command's output at a newline)."""
        if byte == ord("\n"):
            line, self.line = self.line, ""
            return "\n" + run_command(line, self.facts) + PROMPT
        if byte in _ERASE:
            if not self.line:
                return ""
            self.line = self.line[:-1]
            return "\b \b"
        if byte == ord("\r"):
            return ""
        if not 0x20 <= byte < 0x7F or len(self.line) >= MAX_LINE:
            self.refused += 1
            return ""
        self.line += chr(byte)
        return chr(byte)

    def _reply(self, part: bytes) -> Any:
        data = list(part) + [0] * (CHUNK - len(part))
        return self.mav.serial_control_encode(
            d.SERIAL_CONTROL_DEV_SHELL, d.SERIAL_CONTROL_FLAG_REPLY, 0, 0, len(part), data
        )


def _pieces(data: bytes) -> list[bytes]:
    return [data[i : i + CHUNK] for i in range(0, len(data), CHUNK)]
