"""The Mini SSC II wire format: frames, pulse widths, what a cycle sends, resync."""

from __future__ import annotations

from companion.actuators import minissc


def test_frame_bytes_and_pulse_widths():
    assert minissc.frame(3, 127) == b"\xff\x03\x7f"
    assert minissc.frame(0, 300) == b"\xff\x00\xfe"  # never the sync byte as a position
    assert [minissc.pulse_us(p) for p in (0, 127, 254)] == [1000, 1500, 2000]
    assert round(1 / minissc.frames_per_second(9600) * 1000, 1) == 3.1  # ms per frame


def test_changed_channels_go_first_and_the_cycle_is_bounded():
    wanted = {0: 100, 1: 127, 2: 127, 3: 50}
    sent = {0: 100, 1: 127, 2: 130, 3: 20}
    plan = minissc.plan_cycle(wanted, sent, refresh_order=[0, 1, 2, 3], room=3)
    assert plan == [(2, 127), (3, 50), (0, 100)]
    assert minissc.plan_cycle(wanted, sent, [0, 1, 2, 3], room=1) == [(2, 127)]
    assert minissc.plan_cycle(wanted, sent, [0, 1, 2, 3], room=0) == []


def test_decoder_resynchronises_after_garbage_and_split_frames():
    dec = minissc.FrameDecoder()
    stream = b"\x01\x02" + minissc.frame(1, 10) + b"\xff\x05" + minissc.frame(2, 20)
    out = dec.feed(stream[:4]) + dec.feed(stream[4:])
    assert out == [(1, 10), (2, 20)]
    assert dec.garbage == 4  # two leading bytes, and the cut-off frame's two


def test_frames_are_each_frame_back_to_back():
    plan = [(0, 300), (3, 127), (7, -5), (1, 254)]
    # Each a sync byte, the servo and its position clamped to 0-254 (frame() is frames()).
    want = bytes((255, 0, 254, 255, 3, 127, 255, 7, 0, 255, 1, 254))
    assert minissc.frames(plan) == want
    assert b"".join(minissc.frame(s, p) for s, p in plan) == want
    assert minissc.frames([]) == b""


def test_frames_refuse_the_sync_byte_as_a_servo_id():
    import pytest

    with pytest.raises(ValueError):
        minissc.frames([(1, 10), (255, 0)])
