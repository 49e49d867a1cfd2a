"""A device's byte stream through its framer and decoder, counted one way everywhere.

The sensor plug-ins read through it on the vehicle and ``companion check`` listens through
it on the bench, so the bench counts frames exactly as the vehicle will. Pure: bytes and
their reception time in, readings out.
"""

from __future__ import annotations

from typing import Generic, TypeVar

from companion.sensors.codec_types import Framer, SentenceDecoder

__all__ = ["FramedStream", "Framer", "SentenceDecoder"]

ReadingT = TypeVar("ReadingT")


class FramedStream(Generic[ReadingT]):
    """Bytes in, readings out; frames decoded and frames refused counted."""

    def __init__(self, framer: Framer, decoder: SentenceDecoder[ReadingT]) -> None:
        self.framer = framer
        self.decoder = decoder

    def feed(self, data: bytes, t_us: int) -> list[ReadingT]:
        """The readings completed by ``data`` (received at ``t_us``)."""
        readings = []
        for sentence in self.framer.feed(data):
            reading = self.decoder.decode(sentence, t_us)
            if reading is not None:
                readings.append(reading)
        return readings

    @property
    def frames_ok(self) -> int:
        """Sentences or frames the decoder accepted."""
        return self.decoder.counters.ok

    @property
    def frames_bad(self) -> int:
        """Bad checksums, undecodable sentences and stretches of garbage."""
        c = self.decoder.counters
        return c.bad_checksum + c.garbage + self.framer.rejected
