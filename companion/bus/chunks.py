"""A bus sample's header and payload in shared memory, as ctypes objects kept per chunk.

A sample's header and payload are read and written in place through their addresses:
iceoryx2's typed accessors (``user_header()``, a cast to a fresh ctypes pointer type) cost
more than the copy itself, several times per sample. A publisher loans its samples from a
fixed pool of chunks (a handful per channel), and its readers receive them at the same few
addresses. The ctypes objects laid over a chunk own nothing (an address and a type), so the
ones made for a chunk the first time give the same bytes every later time: kept by the
payload's address, they spare two or three objects at every sample of every channel, most of
what a publish or a receive cost besides iceoryx2's own calls.
"""

from __future__ import annotations

import ctypes
from functools import cache
from typing import Any

# Chunks kept per writer or reader: a pool is far smaller; one that keeps giving new
# addresses (a writer that came back, a grown pool) starts the collection again.
MAX_CHUNKS = 256


class SampleHeader(ctypes.Structure):
    """Prepended to every bus sample: which writer sent it, and its running number."""

    _fields_ = [("writer_id", ctypes.c_uint64), ("seq", ctypes.c_uint64)]


header_at = SampleHeader.from_address


@cache
def payload_box(msg_type: type[ctypes.Structure]) -> type[ctypes.Structure]:
    """A structure of one field, ``msg``, of ``msg_type``: laid over a payload, assigning a
    message to the field copies its bytes in one C ``memcpy``, about half of what a byte
    view's slice assignment costs (and ``ctypes.memmove`` goes through libffi, several
    times that)."""
    return type(f"{msg_type.__name__}Box", (ctypes.Structure,), {"_fields_": [("msg", msg_type)]})


class WriterChunks:
    """A writer's chunks: each one's header and the box over its payload."""

    def __init__(self, msg_type: type[ctypes.Structure]) -> None:
        self._box_at = payload_box(msg_type).from_address
        self.kept: dict[int, tuple[SampleHeader, Any]] = {}

    def add(self, sample: Any) -> tuple[SampleHeader, Any]:
        """The header and payload box of a loaned chunk not seen before, kept."""
        if len(self.kept) >= MAX_CHUNKS:
            self.kept.clear()
        address = sample.payload_ptr
        chunk = (header_at(sample.user_header_ptr), self._box_at(address))
        self.kept[address] = chunk
        return chunk


class ReaderChunks:
    """A reader's chunks: each one's header (None when the reader counts no losses) and
    its payload as a byte array (for ``from_buffer_copy``)."""

    def __init__(self, msg_type: type[ctypes.Structure], headers: bool) -> None:
        self._bytes_at = (ctypes.c_char * ctypes.sizeof(msg_type)).from_address
        self._headers = headers
        self.kept: dict[int, tuple[SampleHeader | None, Any]] = {}

    def add(self, sample: Any) -> tuple[SampleHeader | None, Any]:
        """The header and payload bytes of a received chunk not seen before, kept."""
        if len(self.kept) >= MAX_CHUNKS:
            self.kept.clear()
        address = sample.payload_ptr
        header = header_at(sample.user_header_ptr) if self._headers else None
        chunk = (header, self._bytes_at(address))
        self.kept[address] = chunk
        return chunk
