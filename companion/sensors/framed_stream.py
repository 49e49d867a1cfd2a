"""A device's byte stream through its framer and decoder, counted one way everywhere.

The sensor plug-ins read through it on the vehicle and ``companion check`` listens through
it on the bench, so the bench counts frames exactly as the vehicle will. Pure: bytes and
their reception time in, readings out.
"""

from __future__ import annotations

from typing import Generic, TypeVar

from companion.sensors.codec_types import Framer, SentenceDecoder

__all__ = ["FramedStream", "Framer", "SentenceDecoder", "spread_since", "spread_stamps"]

ReadingT = TypeVar("ReadingT")


class FramedStream(Generic[ReadingT]):
    """Bytes in, readings out; frames decoded and frames refused counted."""

    def __init__(self, framer: Framer, decoder: SentenceDecoder[ReadingT]) -> None:
        self.framer = framer
        self.decoder = decoder

    def feed(self, data: bytes, t_us: int) -> list[ReadingT]:
        """The readings completed by ``data`` (received at ``t_us``)."""
        sentences = self.framer.feed(data)
        return [reading for reading, _t in self._decode(sentences, [t_us] * len(sentences))]

    def feed_spaced(
        self, data: bytes, t_us: int, since_us: int | None, period_us: float
    ) -> list[tuple[ReadingT, int]]:
        """As ``feed`` for a device that sends one frame per sample, every ``period_us``:
        the readings with each frame's own time (``spread_stamps``), not the read's."""
        sentences = self.framer.feed(data)
        return self._decode(sentences, spread_stamps(len(sentences), t_us, since_us, period_us))

    def _decode(self, sentences: list[bytes], stamps: list[int]) -> list[tuple[ReadingT, int]]:
        """Each sentence decoded at its stamp; the readings with their stamps."""
        out = []
        for sentence, t in zip(sentences, stamps, strict=True):
            reading = self.decoder.decode(sentence, t)
            if reading is not None:
                out.append((reading, t))
        return out

    @property
    def frames_ok(self) -> int:
        """Sentences or frames the decoder accepted."""
        return self.decoder.counters.ok

    @property
    def frames_bad(self) -> int:
        """Bad checksums, undecodable sentences and stretches of garbage."""
        c = self.decoder.counters
        return c.bad_checksum + c.garbage + self.framer.rejected


def spread_stamps(n: int, t_us: int, since_us: int | None, period_us: float) -> list[int]:
    """When the ``n`` frames one read completed were sent: the last at the read's ``t_us``,
    each earlier one a device period before the next, and all after the previous read
    (``since_us``), which had found none of them.

    A reader that fell behind (a busy board) finds several samples of a periodic device
    waiting; stamped alike, a navigator would take all but one as no time passing.
    """
    if n <= 1:
        return [t_us] * n
    step = period_us if period_us > 0 else float("inf")
    if since_us is not None:
        step = min(step, (t_us - since_us) / n)
    if step == float("inf"):
        step = 0.0
    step = max(step, 0.0)
    return [t_us - round((n - 1 - i) * step) for i in range(n)]


def spread_since(last_read_us: int | None, reported_us: int | None) -> int | None:
    """The time no frame of a read can be stamped before: the previous read's (it found
    none of them), and the driver's last counter report (which counted every sample
    stamped up to then, so a frame stamped before it would be counted twice or never)."""
    return max(last_read_us or 0, reported_us or 0) or None
