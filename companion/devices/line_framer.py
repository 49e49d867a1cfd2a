"""Cut a byte stream into ``$...`` sentences; count what is not a sentence and move on."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class FramerCounters:
    frames: int = 0
    garbage_bytes: int = 0
    garbage_runs: int = 0  # stretches of bytes outside any sentence
    overlong: int = 0


class LineFramer:
    """Feed arbitrary chunks; get back whole sentences (without the line ending)."""

    def __init__(self, max_len: int = 200) -> None:
        self.max_len = max_len
        self.buf = bytearray()
        self.counters = FramerCounters()

    def feed(self, data: bytes) -> list[bytes]:
        self.buf += data
        out: list[bytes] = []
        while True:
            start = self.buf.find(b"$")
            if start < 0:
                self._garbage(len(self.buf))
                self.buf.clear()
                return out
            if start:
                self._garbage(start)
                del self.buf[:start]
            end = self._line_end()
            if end < 0:
                if len(self.buf) > self.max_len:  # no end in sight: resynchronise
                    self.counters.overlong += 1
                    del self.buf[:1]
                    continue
                return out
            line = bytes(self.buf[:end])
            del self.buf[: end + 1]
            if len(line) > self.max_len:
                self.counters.overlong += 1
                continue
            nested = line.rfind(b"$")
            if nested > 0:  # a sentence cut short by the next one
                self.counters.garbage_bytes += nested
                line = line[nested:]
            self.counters.frames += 1
            out.append(line)

    def _garbage(self, count: int) -> None:
        # Line endings between sentences are not garbage.
        if count and any(b not in (0x0A, 0x0D) for b in self.buf[:count]):
            self.counters.garbage_runs += 1
        self.counters.garbage_bytes += count

    def _line_end(self) -> int:
        for i, byte in enumerate(self.buf):
            if byte in (0x0A, 0x0D):
                return i
        return -1
