"""The simulated servo card: what a Mini SSC II makes of the bytes the vehicle sends it.

Read from the card's protocol, not from the vehicle's encoder, so a bug in one cannot
hide behind the same bug in the other. The protocol (Scott Edwards Electronics, Mini SSC
II manual): a command is three bytes at 2400 or 9600 baud, 8N1,

    0xFF (sync), servo number 0-254, position 0-254

and the card starts a command only on the sync byte: anything between a complete command
and the next 0xFF is ignored, and a sync byte inside a command starts it over. Positions
map to pulse widths the airframe file's travel describes; here they become the flight
model's normalised surface commands.
"""

from __future__ import annotations

from dataclasses import dataclass

SYNC_BYTE = 0xFF
COMMAND_LENGTH = 3


@dataclass
class ServoCommand:
    """One complete command off the wire."""

    servo: int
    position: int


class MiniSscReader:
    """Bytes in, commands out, resynchronising the way the card does; never raises."""

    def __init__(self) -> None:
        self._command = bytearray()  # starts with the sync byte when a command is open
        self.commands = 0
        self.ignored = 0  # bytes outside any command

    def read(self, data: bytes) -> list[ServoCommand]:
        """The commands completed by ``data``, in wire order."""
        done: list[ServoCommand] = []
        for byte in data:
            if byte == SYNC_BYTE:
                self.ignored += len(self._command)  # a command cut short by a new sync
                self._command = bytearray((byte,))
                continue
            if not self._command:
                self.ignored += 1
                continue
            self._command.append(byte)
            if len(self._command) == COMMAND_LENGTH:
                done.append(ServoCommand(self._command[1], self._command[2]))
                self.commands += 1
                self._command = bytearray()
        return done
