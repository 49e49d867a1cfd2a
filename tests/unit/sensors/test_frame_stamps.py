"""Frames a late read finds together get their own times: the last at the read, the others
a device period apart, none at or before the previous read."""

from __future__ import annotations

import itertools

from hypothesis import given
from hypothesis import strategies as st

from companion.sensors.framed_stream import FramedStream, spread_stamps
from companion.sensors.line_framer import LineFramer
from companion.sensors.vectornav import VectorNavDecoder
from tests.unit.sensors.test_vectornav import IMU, xor8

GOOD = f"$VNIMU,{IMU}*{xor8('VNIMU,' + IMU)}\r\n".encode()


def test_three_samples_of_a_100_hz_imu_found_late_are_10_ms_apart():
    assert spread_stamps(3, 1_000_000, 970_000, 10_000.0) == [980_000, 990_000, 1_000_000]


def test_a_read_soon_after_the_last_packs_them_between_the_two():
    assert spread_stamps(3, 1_000_000, 994_000, 10_000.0) == [996_000, 998_000, 1_000_000]


def test_one_frame_or_none_keeps_the_reads_time():
    assert spread_stamps(1, 5, 0, 10.0) == [5] and spread_stamps(0, 5, 0, 10.0) == []


@given(
    n=st.integers(2, 50),
    since=st.integers(0, 10**9),
    gap=st.integers(1, 10**6),
    period=st.one_of(st.just(0.0), st.floats(1.0, 1e6)),
)
def test_stamps_rise_end_at_the_read_and_stay_after_the_previous(n, since, gap, period):
    t = since + gap
    stamps = spread_stamps(n, t, since, period)
    assert stamps[-1] == t and stamps == sorted(stamps)
    if gap >= 2 * n:  # a microsecond or more between frames: none lands on the last read
        assert stamps[0] > since and len(set(stamps)) == n
    assert all(b - a <= max(period, gap / n) + 1 for a, b in itertools.pairwise(stamps))


def test_a_stream_stamps_each_imu_frame_of_a_burst_by_its_place():
    stream = FramedStream(LineFramer(), VectorNavDecoder())
    got = stream.feed_spaced(GOOD * 4, 2_000_000, 1_900_000, 10_000.0)
    assert [t for _reading, t in got] == [1_970_000, 1_980_000, 1_990_000, 2_000_000]
    assert [r.imu.t_us for r, _t in got] == [1_970_000, 1_980_000, 1_990_000, 2_000_000]
