"""What every sensor codec offers the plug-in that runs it: framers and decoders.

A framer cuts a byte stream into the device's sentences or frames; a decoder turns one
sentence and its reception time into a reading or a counted refusal. The codecs in this
package satisfy these structurally (a test checks each); ``SerialSensor`` runs any pair.
"""

from __future__ import annotations

from typing import Protocol, TypeVar, runtime_checkable

ReadingT_co = TypeVar("ReadingT_co", covariant=True)


@runtime_checkable
class DecoderCounters(Protocol):
    """The counters every sentence decoder keeps."""

    ok: int
    bad_checksum: int
    garbage: int


@runtime_checkable
class Framer(Protocol):
    """Cuts a byte stream into the device's sentences or frames."""

    @property
    def rejected(self) -> int:
        """How many stretches of bytes it has refused as not a sentence or frame."""
        ...

    def feed(self, data: bytes) -> list[bytes]:
        """The whole sentences or frames completed by ``data``."""
        ...

    def rest_bytes(self) -> int:
        """Bytes still to come of a frame begun but not ended, at least (0: none begun, or
        its length unknown): a reader may wait for them instead of waking for each piece."""
        ...


@runtime_checkable
class SentenceDecoder(Protocol[ReadingT_co]):
    """A pure decoder: one sentence and its reception time in, a reading or None out."""

    @property
    def counters(self) -> DecoderCounters:
        """What it has accepted and refused."""
        ...

    def decode(self, sentence: bytes, t_us: int) -> ReadingT_co | None:
        """The reading in one sentence; None when refused (and counted)."""
        ...
