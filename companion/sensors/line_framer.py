"""Cut a byte stream into ``$...`` text sentences; count what is not a sentence and move on.

For the ASCII line protocols of the vehicle's devices (NMEA 0183, the OS-3000 ``$C``
sentence, VectorNav ASCII): a sentence starts with ``$`` and ends at CR or LF. Chunks may
split a sentence anywhere; it comes out whole once its line ending arrives. A ``$`` inside
a sentence means the sentence was cut short (none of these protocols allows ``$`` in a
field), so framing restarts there. Pure: no port, no clock.
"""

from __future__ import annotations

import re
from collections import deque
from dataclasses import dataclass

_STOP = re.compile(rb"[\r\n$]")  # what ends the sentence in progress
_EOL = re.compile(rb"[\r\n]")
DEFAULT_MAX_LEN = 200
RECENT_FRAMES = 8  # sentences whose lengths say how long the next one is, at least


@dataclass
class FramerCounters:
    """What the framer has seen since it was made."""

    frames: int = 0  # sentences handed out
    garbage_bytes: int = 0  # bytes outside any sentence (line endings excepted)
    garbage_runs: int = 0  # unbroken stretches of such bytes
    overlong: int = 0  # lines dropped for exceeding max_len


class LineFramer:
    """Feed arbitrary chunks; get back whole sentences, ``$`` first, line ending removed."""

    def __init__(self, max_len: int = DEFAULT_MAX_LEN) -> None:
        self.max_len = max_len  # longest sentence kept, counting the '$', not the CR/LF
        self.counters = FramerCounters()
        self._line: bytearray | None = None  # the sentence in progress, None between them
        self._discarding = False  # inside the tail of an over-long line
        self._in_run = False  # the last bytes outside a sentence were garbage
        self._recent: deque[int] = deque(maxlen=RECENT_FRAMES)  # their lengths, '$' on
        self._begun_in_feed = False  # the sentence in progress began in the last chunk

    @property
    def rejected(self) -> int:
        """Over-long lines and runs of garbage: what a driver counts as bad frames."""
        return self.counters.overlong + self.counters.garbage_runs

    def feed(self, data: bytes) -> list[bytes]:
        """The sentences completed by this chunk, in order."""
        self._begun_in_feed = False
        if (whole := self._one_whole_sentence(data)) is not None:
            return [whole]
        out: list[bytes] = []
        pos, end = 0, len(data)
        while pos < end:
            if self._line is None:
                start = data.find(b"$", pos)
                self._outside(data[pos : end if start < 0 else start])
                if start < 0:
                    break
                self._begin()
                pos = start + 1
                continue
            stop = _STOP.search(data, pos)
            cut = end if stop is None else stop.start()
            self._line += data[pos:cut]
            if len(self._line) > self.max_len:
                self._overlong(ended=stop is not None)
            elif stop is None:
                break
            elif data[cut] == 0x24:  # '$': the sentence in progress was cut short
                self._garbage(len(self._line))
                self._line = None
            else:
                out.append(bytes(self._line))
                self.counters.frames += 1
                self._recent.append(len(self._line))
                self._line = None
            pos = end if stop is None else (cut if data[cut] == 0x24 else cut + 1)
        return out

    def rest_bytes(self) -> int:
        """Bytes still to come of a sentence the last chunk began, at least: the shortest
        of the last few sentences and its line ending's first byte, less what has come (0:
        none begun in that chunk, or no sentence seen yet).

        A USB serial adapter hands a sentence over in pieces (every millisecond in low
        latency mode: ten reads of a 98-byte VectorNav sentence at 115200 baud), each of
        which would wake its reader for a sentence it cannot decode yet. Only the chunk
        that began it says: a reader waits once a sentence, then takes the last pieces as
        they come, so that the sentence is no later for the wait."""
        if self._line is None or not self._begun_in_feed or not self._recent:
            return 0
        return max(0, min(self._recent) - len(self._line)) + 1

    def bytes_until(self, sentences: int) -> int:
        """Bytes still to come before ``sentences`` more are whole (the one in progress
        the first of them), at least: each as long as the shortest of the last few and its
        line ending's first byte, less what has come of the one in progress (0: none asked,
        or no sentence seen yet). A reader with nothing to do before then may sleep until
        that many bytes are waiting (``ReopeningSerial.wake_after``)."""
        if sentences <= 0 or not self._recent:
            return 0
        begun = len(self._line) if self._line is not None else 0
        return max(0, sentences * (min(self._recent) + 1) - begun)

    def _one_whole_sentence(self, data: bytes) -> bytes | None:
        """``data`` as one sentence when it is exactly one, from its ``$`` to its line
        ending, between sentences: what a device's read nearly always finds. The loop in
        ``feed`` would come to the same sentence and the same counters (the line ending
        after it is no garbage) through a dozen calls; this is a few tests in C."""
        if self._line is not None or self._discarding or not data.startswith(b"$"):
            return None
        body = data.rstrip(b"\r\n")
        if (
            len(body) == len(data)
            or len(body) > self.max_len
            or body.count(b"$") != 1
            or b"\r" in body
            or b"\n" in body
        ):
            return None
        self.counters.frames += 1
        self._recent.append(len(body))
        self._in_run = False  # as _begin() does
        return body

    def _begin(self) -> None:
        self._begun_in_feed = True
        self._line = bytearray(b"$")
        self._discarding = False
        self._in_run = False

    def _overlong(self, ended: bool) -> None:
        self.counters.overlong += 1
        self._line = None
        # Without its line ending yet, the rest of the line is still to come: skip it
        # quietly rather than count it as garbage a second time.
        self._discarding = not ended

    def _outside(self, chunk: bytes) -> None:
        if self._discarding:
            eol = _EOL.search(chunk)
            if eol is None:
                return
            self._discarding = False
            chunk = chunk[eol.end() :]
        # Line endings between sentences are normal, not garbage.
        self._garbage(len(chunk.translate(None, b"\r\n")))

    def _garbage(self, count: int) -> None:
        if count:
            self.counters.garbage_bytes += count
            if not self._in_run:
                self.counters.garbage_runs += 1
                self._in_run = True
