"""The legacy text link's frames: the thesis's ATT/POS text formats, 25-byte NUL-padded
encoding, and the reader that turns a noisy, split, paused byte stream into START/STOP."""

from __future__ import annotations

import pytest

from bridges.text_link.frames import (
    FrameError,
    FrameReader,
    att_text,
    encode_frame,
    pos_text,
)

START = b"START".ljust(25, b"\x00")
STOP = b"STOP".ljust(25, b"\x00")


# --- text formats ---


def test_the_thesis_examples_exactly():
    assert att_text(82.5, 33.6, 18.9) == "ATT 82.5 33.6 18.9"
    assert pos_text(145.8292, -37.1583) == "POS 145.8292 -37.1583"


def test_attitude_has_one_decimal_and_position_four():
    assert att_text(1, 2, 3) == "ATT 1.0 2.0 3.0"
    assert pos_text(145, -37) == "POS 145.0000 -37.0000"


def test_negative_signs_but_never_a_plus_sign():
    assert att_text(-12.34, -5.0, 10.0) == "ATT -12.3 -5.0 10.0"
    assert pos_text(-58.38, 34.6) == "POS -58.3800 34.6000"
    assert "+" not in att_text(12.0, 5.0, 10.0) + pos_text(58.0, 34.0)


def test_yaw_is_a_compass_heading():
    assert att_text(0, 0, -90) == "ATT 0.0 0.0 270.0"
    assert att_text(0, 0, 360) == "ATT 0.0 0.0 0.0"
    assert att_text(0, 0, 450) == "ATT 0.0 0.0 90.0"
    assert att_text(0, 0, -180) == "ATT 0.0 0.0 180.0"


def test_a_heading_that_rounds_up_to_360_is_0():
    assert att_text(0, 0, 359.96) == "ATT 0.0 0.0 0.0"
    assert att_text(0, 0, -0.04) == "ATT 0.0 0.0 0.0"
    assert att_text(0, 0, 359.94) == "ATT 0.0 0.0 359.9"


def test_rounding_is_printfs():
    assert att_text(0.05, 0.15, 0.26) == "ATT 0.1 0.1 0.3"
    assert att_text(-0.05, 1.04, 1.06) == "ATT -0.1 1.0 1.1"
    assert pos_text(145.82916, -37.91054) == "POS 145.8292 -37.9105"
    assert pos_text(0.00005, -0.00006) == "POS 0.0001 -0.0001"


def test_the_longest_texts_fit_a_frame():
    att, pos = att_text(-180, -90, 359.9), pos_text(-180, -90)
    assert att == "ATT -180.0 -90.0 359.9"
    assert pos == "POS -180.0000 -90.0000"
    assert encode_frame(att).endswith(b"\x00") and encode_frame(pos).endswith(b"\x00")


# --- encoding ---


def test_a_frame_is_25_bytes_of_text_then_nuls():
    frame = encode_frame("ATT 82.5 33.6 18.9")
    assert len(frame) == 25
    assert frame == b"ATT 82.5 33.6 18.9" + b"\x00" * 7


def test_24_characters_fit_with_their_nul_and_25_do_not():
    assert encode_frame("X" * 24) == b"X" * 24 + b"\x00"
    with pytest.raises(FrameError):
        encode_frame("X" * 25)
    assert encode_frame("") == b"\x00" * 25


def test_non_ascii_text_is_refused():
    with pytest.raises(UnicodeEncodeError):
        encode_frame("ATT 1.0 2.0 3.0°")


# --- reading ---


def test_whole_frames_give_their_commands():
    reader = FrameReader()
    assert reader.feed(START, 0.0) == ["START"]
    assert reader.feed(STOP, 0.0) == ["STOP"]
    assert reader.counts.frames == 2


def test_a_frame_fed_byte_by_byte_comes_out_once():
    reader = FrameReader()
    out = [cmd for i in range(25) for cmd in reader.feed(START[i : i + 1], i * 0.001)]
    assert out == ["START"]


def test_several_frames_in_one_chunk_come_out_in_order():
    reader = FrameReader()
    assert reader.feed(START + STOP + STOP + START, 0.0) == ["START", "STOP", "STOP", "START"]


def test_noise_between_frames_is_counted_and_skipped():
    reader = FrameReader()
    assert reader.feed(START + b"\xff\x93\x01" + STOP, 0.0) == ["START", "STOP"]
    assert reader.counts.noise_bytes == 3
    assert reader.counts.dropped_texts == 0


def test_noise_inside_a_frame_drops_that_frame():
    reader = FrameReader()
    damaged = b"ST\xffOP".ljust(25, b"\x00")
    assert reader.feed(damaged + START, 0.0) == ["START"]
    assert reader.counts.noise_bytes == 1
    assert reader.counts.dropped_texts == 1
    assert reader.counts.frames == 1


def test_an_over_long_text_is_dropped_once_and_the_next_frame_decodes():
    reader = FrameReader()
    assert reader.feed(b"A" * 40 + b"\x00" + START, 0.0) == ["START"]
    assert reader.counts.overlong == 1
    assert reader.counts.unknown == 0


def test_texts_that_are_not_commands_are_counted_unknown():
    reader = FrameReader()
    data = encode_frame("HELLO") + encode_frame("ATT 1 2 3") + encode_frame("start")
    assert reader.feed(data, 0.0) == []
    assert reader.counts.unknown == 3
    assert reader.counts.frames == 0


def test_a_partial_frame_left_hanging_is_dropped_after_a_pause():
    reader = FrameReader(gap_s=0.5)
    assert reader.feed(b"STA", 0.0) == []
    assert reader.feed(START, 0.6) == ["START"]
    assert reader.counts.partial == 1
    assert reader.counts.unknown == 0


def test_a_short_pause_inside_a_frame_is_not_a_partial():
    reader = FrameReader(gap_s=0.5)
    assert reader.feed(b"STA", 0.0) == []
    assert reader.feed(b"RT\x00", 0.4) == ["START"]
    assert reader.counts.partial == 0


def test_cr_and_lf_end_a_frame_like_nul():
    reader = FrameReader()
    assert reader.feed(b"START\r\n", 0.0) == ["START"]
    assert reader.feed(b"STOP\n", 0.0) == ["STOP"]
    assert reader.counts.unknown == 0


def test_padding_alone_gives_nothing():
    reader = FrameReader()
    assert reader.feed(b"\x00" * 100, 0.0) == []
    assert reader.feed(b"", 5.0) == []
    c = reader.counts
    assert (c.frames, c.unknown, c.overlong, c.partial, c.noise_bytes) == (0, 0, 0, 0, 0)


def test_a_pause_after_an_unterminated_over_long_text_resynchronises():
    reader = FrameReader(gap_s=0.5)
    assert reader.feed(b"A" * 40, 0.0) == []
    assert reader.feed(START, 1.0) == ["START"]
