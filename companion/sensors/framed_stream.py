"""A device's byte stream through its framer and decoder, counted one way everywhere.

The sensor plug-ins read through it on the vehicle and ``companion check`` listens through
it on the bench, so the bench counts frames exactly as the vehicle will. Pure: bytes and
their reception time in, readings out.
"""

from __future__ import annotations

from typing import Generic, Protocol, TypeVar

ReadingT = TypeVar("ReadingT")
ReadingT_co = TypeVar("ReadingT_co", covariant=True)


class DecoderCounters(Protocol):
    """The counters every sentence decoder keeps."""

    ok: int
    bad_checksum: int
    garbage: int


class Framer(Protocol):
    """Cuts a byte stream into the device's sentences or frames."""

    @property
    def rejected(self) -> int:
        """How many stretches of bytes it has refused as not a sentence or frame."""
        ...

    def feed(self, data: bytes) -> list[bytes]:
        """The whole sentences or frames completed by ``data``."""
        ...


class SentenceDecoder(Protocol[ReadingT_co]):
    """A pure decoder: one sentence and its reception time in, a reading or None out."""

    @property
    def counters(self) -> DecoderCounters:
        """What it has accepted and refused."""
        ...

    def decode(self, sentence: bytes, t_us: int) -> ReadingT_co | None:
        """The reading in one sentence; None when refused (and counted)."""
        ...


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
