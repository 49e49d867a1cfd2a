"""The thesis's data-link frames: 25 bytes of ASCII, NUL-terminated and NUL-padded.

Down (vehicle to ground) the thesis sent ``ATT <roll> <pitch> <yaw>`` in degrees with one
decimal and ``POS <longitude> <latitude>`` with four; up, ``START`` and ``STOP``. The
numbers are printed as C's ``printf("%.1f")`` and ``("%.4f")`` print them (Python's float
formatting rounds the same way): a minus sign only when negative, no plus sign, no padding inside
the text. Yaw is the compass heading, 0 to 360, as the thesis's OS-3000 gave it.

Reading is forgiving of the line, not of the content: a frame ends at a NUL (or CR/LF, so
a terminal can type commands); the NULs after it are padding. A byte that is not printable
ASCII is line noise: the text gathered so far is dropped and the next printable byte
starts a new frame. A text longer than a frame is dropped up to its terminator, and a
partial frame left hanging longer than ``gap_s`` is dropped when the next byte comes.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

log = logging.getLogger(__name__)

FRAME_BYTES = 25
MAX_TEXT = FRAME_BYTES - 1  # the terminating NUL is part of the frame
TERMINATORS = frozenset(b"\x00\r\n")
COMMANDS = ("START", "STOP")


class FrameError(ValueError):
    """A text that does not fit one frame."""


def encode_frame(text: str) -> bytes:
    """``text`` as one 25-byte frame: ASCII, then NULs to the full length."""
    raw = text.encode("ascii")
    if len(raw) > MAX_TEXT:
        raise FrameError(f"{text!r} is {len(raw)} bytes; a frame holds {MAX_TEXT} and a NUL")
    return raw.ljust(FRAME_BYTES, b"\x00")


def att_text(roll_deg: float, pitch_deg: float, yaw_deg: float) -> str:
    """``ATT roll pitch yaw``; yaw as a heading in [0, 360)."""
    heading = f"{yaw_deg % 360.0:.1f}"
    if heading == "360.0":  # 359.96 rounds up: the same heading as 0
        heading = "0.0"
    return f"ATT {roll_deg:.1f} {pitch_deg:.1f} {heading}"


def pos_text(lon_deg: float, lat_deg: float) -> str:
    """``POS longitude latitude``."""
    return f"POS {lon_deg:.4f} {lat_deg:.4f}"


@dataclass
class ReaderCounts:
    """What the reader saw, for the status log."""

    frames: int = 0  # known commands
    unknown: int = 0  # complete texts that are not a command
    overlong: int = 0  # texts longer than a frame
    partial: int = 0  # texts cut off by a pause on the line
    noise_bytes: int = 0  # bytes that are not printable ASCII
    dropped_texts: int = 0  # texts cut short by noise


class FrameReader:
    """Turns bytes from the ground station into commands, resynchronising after damage."""

    def __init__(self, commands: tuple[str, ...] = COMMANDS, gap_s: float = 0.5) -> None:
        self.commands = frozenset(commands)
        self.gap_s = gap_s
        self.counts = ReaderCounts()
        self._text = bytearray()
        self._skipping = False  # inside an over-long text, until its terminator
        self._last_byte_s: float | None = None

    def feed(self, data: bytes, now_s: float) -> list[str]:
        """The commands completed by ``data``, in order."""
        last = self._last_byte_s
        if data and last is not None and now_s - last > self.gap_s:
            self._pause()
        if data:
            self._last_byte_s = now_s
        found: list[str] = []
        for byte in data:
            if byte in TERMINATORS:
                self._finish(found)
            elif 0x20 <= byte < 0x7F:
                self._printable(byte)
            else:
                self.counts.noise_bytes += 1
                if self._text:
                    self.counts.dropped_texts += 1
                self._text.clear()
                self._skipping = False
        return found

    def _pause(self) -> None:
        """A silent line ends whatever frame was under way: the next byte starts afresh."""
        if self._text:
            self.counts.partial += 1
            log.debug("partial frame %r dropped after a pause", bytes(self._text))
            self._text.clear()
        self._skipping = False

    def _printable(self, byte: int) -> None:
        if self._skipping:
            return
        self._text.append(byte)
        if len(self._text) > MAX_TEXT:
            self.counts.overlong += 1
            log.debug("over-long frame %r... dropped", bytes(self._text[:12]))
            self._text.clear()
            self._skipping = True

    def _finish(self, found: list[str]) -> None:
        self._skipping = False
        if not self._text:
            return  # padding
        text = self._text.decode("ascii").strip()
        self._text.clear()
        if text in self.commands:
            self.counts.frames += 1
            found.append(text)
        else:
            self.counts.unknown += 1
            log.info("unknown message %r dropped", text)
