"""Fuzzing the legacy text link's FrameReader: arbitrary bytes never break it, and real
START/STOP frames survive any line noise between them, however the bytes are chunked."""

from __future__ import annotations

import string

from hypothesis import given, settings
from hypothesis import strategies as st

from bridges.text_link.frames import FrameReader, encode_frame

LETTERS = frozenset(string.ascii_letters.encode())
# Noise that can never spell a command: any byte but an ASCII letter...
NOISE_BYTE = st.sampled_from(sorted(set(range(256)) - LETTERS))
# ...ending in a NUL, CR, LF or a non-printable byte, so it cannot run into the next frame.
NOISE_END = st.sampled_from([0x00, 0x0A, 0x0D, 0x01, 0x1B, 0x7F, 0x80, 0x93, 0xFF])
NOISE = st.builds(
    lambda body, end: bytes([*body, end]), st.lists(NOISE_BYTE, max_size=60), NOISE_END
)
WORDS = st.lists(st.sampled_from(["START", "STOP"]), min_size=1, max_size=12)


def feed_in_chunks(reader, data, sizes, gap_s):
    """Feed ``data`` in chunks of the given sizes (cycled), ``gap_s`` apart."""
    found, i, n = [], 0, 0
    while i < len(data):
        size = sizes[n % len(sizes)]
        found += reader.feed(data[i : i + size], n * gap_s)
        i, n = i + size, n + 1
    return found


@settings(max_examples=200, deadline=None)
@given(st.lists(st.binary(max_size=80), max_size=20), st.floats(0.0, 2.0))
def test_arbitrary_bytes_never_raise(chunks, gap_s):
    reader = FrameReader(gap_s=0.5)
    found = []
    for n, chunk in enumerate(chunks):
        found += reader.feed(chunk, n * gap_s)
    assert set(found) <= {"START", "STOP"}
    assert reader.counts.frames == len(found)


@settings(max_examples=200, deadline=None)
@given(
    WORDS,
    st.lists(NOISE, min_size=1, max_size=13),
    st.lists(st.integers(1, 40), min_size=1, max_size=8),
)
def test_every_real_frame_survives_the_noise_around_it(words, noises, sizes):
    data = b"".join(noises[n % len(noises)] + encode_frame(w) for n, w in enumerate(words))
    data += noises[len(words) % len(noises)]
    reader = FrameReader(gap_s=0.5)
    assert feed_in_chunks(reader, data, sizes, gap_s=0.01) == words
    assert reader.counts.frames == len(words)
