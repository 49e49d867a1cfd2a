"""The SBUS codec: frames written bit by bit as the receiver sends them (not with the
codec's own packing: tests/support/sbus.py), garbage in between, and the receiver's flags."""

from __future__ import annotations

import random

from hypothesis import given
from hypothesis import strategies as st

from companion.sensors.rc_channels import RC_PARAMS, sticks, switch_position
from companion.sensors.sbus import SbusDecoder, raw_to_us
from tests.support.sbus import frame

DEFAULTS = {p.name: p.default for p in RC_PARAMS}


def test_channels_and_flags_come_through():
    channels = [172, 992, 1811, 0, 2047, *range(100, 1100, 100), 555]
    dec = SbusDecoder()
    (f,) = dec.feed(frame(channels, flags=0b1001))
    assert list(f.channels) == channels
    assert f.ch17 and not f.ch18 and f.failsafe and not f.frame_lost
    assert (raw_to_us(172), raw_to_us(992), raw_to_us(1811)) == (988, 1500, 2012)


def test_frames_split_anywhere_and_garbage_between_are_survived():
    good = frame([992] * 16)
    stream = b"\x0f\x0f\xff" + good + bytes(range(256)) + good + b"\x0f" * 30 + good
    dec = SbusDecoder()
    frames = []
    rng = random.Random(1)
    i = 0
    while i < len(stream):
        n = rng.randint(1, 40)
        frames += dec.feed(stream[i : i + n])
        i += n
    assert len(frames) >= 3
    assert all(list(f.channels) == [992] * 16 for f in frames[-1:])
    assert dec.counters.bad_frames > 0 and dec.counters.garbage_bytes > 0


def test_bad_end_byte_or_flag_bits_refuse_the_frame():
    dec = SbusDecoder()
    assert dec.feed(frame([992] * 16, end=0x55)) == []
    assert dec.feed(frame([992] * 16, flags=0x10)) == []
    assert dec.counters.ok == 0 and dec.counters.bad_frames >= 2
    assert len(dec.feed(frame([992] * 16, end=0x14))) == 1  # SBUS2 telemetry slot


@given(st.binary(max_size=600))
def test_any_bytes_never_raise(data):
    dec = SbusDecoder()
    for f in dec.feed(data):
        assert all(0 <= c <= 2047 for c in f.channels)
    assert dec._scan.pending < 25


def test_sticks_follow_calibration_and_reversal():
    pulses = [1900, 1100, 1500, 1500, 1500, 1500, 1500, 2000]
    s = sticks(pulses, DEFAULTS)
    assert (s.roll, s.pitch, s.yaw, s.throttle) == (1.0, -1.0, 0.0, 0.5)
    assert s.mode_switch == 5 and not s.throttle_low
    s = sticks(pulses, DEFAULTS | {"RC1_REVERSED": 1.0, "FLTMODE_CH": 0.0})
    assert s.roll == -1.0 and s.mode_switch == -1
    assert sticks([1500, 1500, 900, 1500], DEFAULTS).throttle_low


def test_switch_bands_are_arduplanes():
    assert [switch_position(p) for p in (1000, 1300, 1400, 1500, 1700, 2000, 0)] == [
        0, 1, 2, 3, 4, 5, -1,
    ]  # fmt: skip
