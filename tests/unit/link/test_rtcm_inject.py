"""GPS_RTCM_DATA fragments joined into whole RTCM messages, as ground stations send them."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from companion.link.rtcm_inject import FRAGMENT_BYTES, RtcmInjectService, RtcmReassembler
from companion.messages import GpsInject
from mavlink_dialect import companion as d


def fragments(message: bytes, seq: int) -> list[tuple[int, int, bytes]]:
    """(flags, len, data) as MAVSDK's Rtk plug-in and QGroundControl split a message: one
    unfragmented GPS_RTCM_DATA up to 180 bytes, else 180-byte fragments, the data field
    always 180 bytes long."""
    parts = [message[i : i + FRAGMENT_BYTES] for i in range(0, len(message), FRAGMENT_BYTES)]
    parts = parts or [b""]
    split = len(parts) > 1
    return [
        (int(split) | (i & 3) << 1 | (seq & 31) << 3, len(p), p.ljust(FRAGMENT_BYTES, b"\0"))
        for i, p in enumerate(parts)
    ]


def joined(joiner: RtcmReassembler, messages: list[bytes]) -> list[bytes]:
    out = []
    for seq, message in enumerate(messages):
        for flags, length, data in fragments(message, seq):
            out += joiner.feed(flags, length, data)
    return out


def test_a_short_message_goes_on_as_it_came():
    joiner = RtcmReassembler()
    assert joined(joiner, [b"\xd3\x00\x13" + bytes(22)]) == [b"\xd3\x00\x13" + bytes(22)]


def test_a_long_message_goes_on_whole_once_its_short_last_fragment_is_in():
    message = bytes(range(256)) * 2  # 512 bytes: 180 + 180 + 152
    joiner = RtcmReassembler()
    (first, second, last) = fragments(message, 5)
    assert joiner.feed(*first) == [] and joiner.feed(*second) == []
    assert joiner.feed(*last) == [message]
    assert (joiner.messages, joiner.dropped) == (1, 0)


def test_four_full_fragments_are_a_whole_message_at_once():
    message = bytes(range(180)) * 4
    assert joined(RtcmReassembler(), [message]) == [message]


def test_a_message_of_two_full_fragments_goes_on_when_the_next_one_begins():
    """No fragment of it is short: only the next message's first tells it has ended."""
    two_full, short = bytes(range(180)) * 2, b"\xd3\x00\x02ab"
    assert joined(RtcmReassembler(), [two_full, short]) == [two_full, short]


def test_a_message_missing_a_fragment_is_dropped_and_counted_and_the_next_goes_on():
    message, following = bytes(range(200)) * 2, b"\xd3next"
    joiner = RtcmReassembler()
    first, _lost, last = fragments(message, 1)
    assert joiner.feed(*first) == [] and joiner.feed(*last) == []
    assert joined(joiner, [following]) == [following]
    assert (joiner.messages, joiner.dropped) == (1, 1)


def test_a_late_fragment_of_a_dropped_message_is_not_taken_for_one():
    """Delivered out of order, its last fragment first: dropped at once, and its first
    fragment, coming after, must not be handed on as a message of its own."""
    message = bytes(range(250)) * 2
    joiner = RtcmReassembler()
    first, second, last = fragments(message, 9)
    for fragment in (last, first, second):
        assert joiner.feed(*fragment) == []
    assert joined(joiner, [b"\xd3ok"]) == [b"\xd3ok"]
    assert joiner.dropped == 1


def test_a_length_over_180_is_refused_and_counted():
    joiner = RtcmReassembler()
    assert joiner.feed(0, 181, bytes(180)) == [] and joiner.feed(0, 255, bytes(180)) == []
    assert (joiner.messages, joiner.dropped) == (0, 2)


def test_a_broken_fragment_loses_its_message_once_and_the_message_before_goes_on():
    two_full = bytes(range(180)) * 2  # whole only once the next message begins
    joiner = RtcmReassembler()
    for fragment in fragments(two_full, 1):
        assert joiner.feed(*fragment) == []
    first, second, last = fragments(bytes(400), 2)
    assert joiner.feed(*first) == [two_full]
    assert joiner.feed(second[0], 200, second[2]) == []  # says 200 bytes of a 180-byte field
    assert joiner.feed(*last) == []  # the rest of that message: not taken for one
    assert (joiner.messages, joiner.dropped) == (1, 1)


@given(st.lists(st.binary(max_size=720), max_size=12))
def test_messages_sent_in_order_come_out_whole_and_in_order(messages):
    out = joined(RtcmReassembler(), [*messages, b"end"])
    assert out == [*messages, b"end"]


@given(st.lists(st.tuples(st.integers(0, 255), st.integers(0, 255), st.binary(max_size=180))))
def test_any_fragments_at_all_never_raise_and_never_give_more_than_four(stream):
    joiner = RtcmReassembler()
    for flags, length, data in stream:
        for message in joiner.feed(flags, length, data):
            assert len(message) <= 4 * FRAGMENT_BYTES


def test_the_link_publishes_whole_messages_and_counts_what_it_refused():
    published: list[GpsInject] = []
    service = RtcmInjectService(published.append, lambda: 42)
    mav = d.MAVLink(None)
    message = bytes(range(250)) * 2
    for flags, length, data in fragments(message, 3):
        service.handle(mav.gps_rtcm_data_encode(flags, length, data), None, 0.0)
    service.handle(mav.gps_rtcm_data_encode(0, 200, bytes(180)), None, 0.0)  # over 180
    assert [m.payload() for m in published] == [message] and published[0].t_us == 42
    assert service.refused == 1
