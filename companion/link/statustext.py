"""STATUSTEXT longer than its 50-byte field, sent in chunks as MAVLink 2 allows.

A text that fits goes out alone with id 0. A longer one gets a non-zero id shared by its
chunks (chunk_seq from 0); the last chunk holds a NUL, so a text whose length is a
multiple of 50 ends with an empty chunk. QGroundControl and MAVProxy put them together.
"""

from __future__ import annotations

from typing import Any

FIELD_BYTES = 50


def chunks(text: str) -> list[bytes]:
    """The text's UTF-8 bytes cut into fields of 50 (the last one shorter, maybe empty)."""
    data = text.encode()
    if len(data) <= FIELD_BYTES:
        return [data]
    parts = [data[i : i + FIELD_BYTES] for i in range(0, len(data), FIELD_BYTES)]
    if len(parts[-1]) == FIELD_BYTES:
        parts.append(b"")  # the NUL that says "last chunk" needs room
    return parts


class StatusTexts:
    """Encodes texts for the link, numbering the long ones."""

    def __init__(self, mav: Any) -> None:
        self.mav = mav
        self.last_id = 0

    def encode(self, text: str, severity: int) -> list[Any]:
        parts = chunks(text)
        if len(parts) == 1:
            return [self.mav.statustext_encode(severity, parts[0])]
        self.last_id = self.last_id % 65535 + 1
        return [
            self.mav.statustext_encode(severity, part, self.last_id, seq)
            for seq, part in enumerate(parts)
        ]
