"""What the ASCII ``$...*hh`` protocols share: the sentence as text, and the 8-bit XOR."""

from __future__ import annotations

import operator
from functools import reduce


def sentence_text(sentence: bytes | str) -> str:
    """The sentence as text without its line ending; "" when it is not ASCII at all."""
    try:
        text = sentence.decode("ascii") if isinstance(sentence, bytes) else sentence
    except UnicodeDecodeError:
        text = ""
    return text.strip("\r\n")


def xor8(payload: str) -> int:
    """The 8-bit XOR of the characters between ``$`` and ``*`` (NMEA, OS-3000, VectorNav)."""
    # On the bytes, so the loop stays in C: the IMU's sentences arrive at 100-400 Hz.
    return reduce(operator.xor, payload.encode("latin-1", "replace"), 0)
