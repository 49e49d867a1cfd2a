"""The TFmini codec: frames written from the manual (tests/support/tfmini.py), split anywhere,
garbage and bad checksums counted and skipped, unreliable readings kept and flagged."""

from __future__ import annotations

import random

from hypothesis import given
from hypothesis import strategies as st

from companion.sensors.tfmini import TfminiDecoder, TfminiFramer, signal_quality
from tests.support.tfmini import frame


def decode_all(stream: bytes, dec: TfminiDecoder | None = None, chunk: int = 0):
    framer, dec = TfminiFramer(), dec or TfminiDecoder()
    frames = []
    if chunk:
        for i in range(0, len(stream), chunk):
            frames += framer.feed(stream[i : i + chunk])
    else:
        frames = framer.feed(stream)
    return framer, [dec.decode(f, 7) for f in frames]


def test_a_frame_gives_metres_and_strength():
    _, (r,) = decode_all(frame(1234, 500))
    assert r is not None
    assert (r.t_us, r.distance_m, r.strength, r.valid) == (7, 12.34, 500, False)  # > 12 m
    _, (r,) = decode_all(frame(523, 500))
    assert r is not None and r.valid and r.distance_m == 5.23
    assert signal_quality(r) == 50


def test_garbage_and_bad_checksums_are_counted_and_skipped():
    bad = bytearray(frame(300))
    bad[8] ^= 0xFF
    # A strength of 0x5959 puts a false header inside a frame; the framer must still resync.
    stream = b"\x00\x59\x12" + bytes(bad) + frame(300, 0x5959) + b"junk" + frame(301)
    framer, readings = decode_all(stream, chunk=4)
    assert [r.distance_m for r in readings if r] == [3.00, 3.01]
    assert framer.counters.bad_frames >= 1
    assert framer.counters.garbage_bytes > 0


def test_unreliable_readings_are_flagged_not_dropped():
    dec = TfminiDecoder(min_m=0.1, max_m=8.0)
    cases = [
        frame(0xFFFF, 20),  # TFmini-S: -1, signal too weak
        frame(0, 2000),  # no distance
        frame(500, 99),  # strength below 100
        frame(500, 0xFFFF),  # overexposed
        frame(900, 2000),  # beyond RNGFND1_MAX
        frame(5, 2000),  # nearer than RNGFND1_MIN
    ]
    _, readings = decode_all(b"".join(cases), dec)
    assert len(readings) == len(cases)
    assert all(r is not None and not r.valid for r in readings)
    assert all(signal_quality(r) == 1 for r in readings if r)
    assert readings[0] is not None and readings[0].distance_m == -1.0
    assert dec.counters.out_of_range == len(cases) and dec.counters.ok == len(cases)


def test_decode_refuses_what_is_not_a_checked_frame():
    dec = TfminiDecoder()
    bad = bytearray(frame(100))
    bad[3] ^= 1
    assert dec.decode(bytes(bad), 0) is None
    assert dec.decode(b"YY\x00", 0) is None
    assert dec.decode(b"\x00" * 9, 0) is None
    assert (dec.counters.bad_checksum, dec.counters.garbage) == (1, 2)


@given(st.binary(max_size=400), st.integers(1, 20))
def test_random_bytes_never_raise(junk, chunk):
    framer, _ = decode_all(junk + frame(250) + junk, chunk=chunk)
    assert framer.counters.ok >= 1


def test_a_long_noisy_stream_loses_only_the_damaged_frames():
    rng = random.Random(3)
    frames = [frame(rng.randrange(10, 1200), rng.randrange(100, 3000)) for _ in range(300)]
    damaged = set(rng.sample(range(300), 30))
    stream = b"".join(
        bytes([f[0], f[1], f[2] ^ 0x40, *f[3:]]) if i in damaged else f
        for i, f in enumerate(frames)
    )
    _, readings = decode_all(stream, chunk=13)
    assert len(readings) == 300 - len(damaged)
