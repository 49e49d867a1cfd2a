"""Fixed-length binary frames found in a byte stream, whatever arrives between them.

SBUS and the TFmini lidar send frames of a fixed length that open with a header and carry
their own check (flag bits and end byte, a checksum). A header byte can also occur inside
data, so a candidate that fails its check costs only its first byte and the search goes on
from the next: a real frame that starts inside a false one is still found. Pure.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Generic, TypeVar

T = TypeVar("T")


@dataclass
class ScanCounters:
    """What the scanner handed out and skipped."""

    ok: int = 0  # frames that passed their check
    bad_frames: int = 0  # a header whose frame did not pass it
    garbage_bytes: int = 0  # bytes skipped while looking for a header


class FixedFrameScanner(Generic[T]):
    """Frames of ``length`` bytes opening with ``header``; ``parse`` turns one into its
    value, or None when it does not check out."""

    def __init__(self, header: bytes, length: int, parse: Callable[[bytes], T | None]) -> None:
        self.header, self.length, self.parse = header, length, parse
        self.counters = ScanCounters()
        self._buf = bytearray()

    @property
    def pending(self) -> int:
        """Bytes held for a frame still arriving (never a whole frame's worth)."""
        return len(self._buf)

    def _partial_header(self) -> int:
        """How many trailing bytes could be the start of a header still arriving."""
        for n in range(min(len(self.header) - 1, len(self._buf)), 0, -1):
            if self._buf.endswith(self.header[:n]):
                return n
        return 0

    def feed(self, data: bytes) -> list[T]:
        """The values of the frames completed by ``data``."""
        buf = self._buf
        buf += data
        out: list[T] = []
        while True:
            start = buf.find(self.header)
            if start < 0:
                keep = self._partial_header()
                self.counters.garbage_bytes += len(buf) - keep
                del buf[: len(buf) - keep]
                return out
            if start:
                self.counters.garbage_bytes += start
                del buf[:start]
            if len(buf) < self.length:
                return out
            value = self.parse(bytes(buf[: self.length]))
            if value is None:  # the header was data: look again from the next byte
                self.counters.bad_frames += 1
                del buf[:1]
                continue
            self.counters.ok += 1
            out.append(value)
            del buf[: self.length]
