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


# XOR-folding an integer of up to 128 bytes onto its lower half, seven times, leaves the
# XOR of all its bytes in the lowest one: (shift, mask) of each fold.
_FOLDS = tuple((bits, (1 << bits) - 1) for bits in (512, 256, 128, 64, 32, 16, 8))
_FOLD_MAX_BYTES = 128


def xor8(payload: str) -> int:
    """The 8-bit XOR of the characters between ``$`` and ``*`` (NMEA, OS-3000, VectorNav)."""
    data = payload.encode("latin-1", "replace")
    if len(data) > _FOLD_MAX_BYTES:
        return reduce(operator.xor, data, 0)
    # The sentence as one integer, folded: seven big-integer steps instead of one Python
    # XOR a character (about 1.5 us less of a 100-character sentence, at 100-400 Hz).
    x = int.from_bytes(data, "little")
    for bits, mask in _FOLDS:
        x = (x >> bits) ^ (x & mask)
    return x
