"""The line framer: whole sentences out of split, noisy, over-long and binary input."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from companion.sensors.line_framer import LineFramer

GGA = b"$GPGGA,120000.00,3754.630738,S,14508.042736,E,1,09,0.9,123.4,M,0.0,M,,*47"
RMC = b"$GPRMC,120000.00,A,3754.630738,S,14508.042736,E,40.0,90.0,231126,,*1F"


def feed_in_pieces(framer: LineFramer, data: bytes, size: int) -> list[bytes]:
    out: list[bytes] = []
    for i in range(0, len(data), size):
        out += framer.feed(data[i : i + size])
    return out


def test_a_clean_stream_gives_every_sentence_and_no_garbage():
    framer = LineFramer()
    assert framer.feed(GGA + b"\r\n" + RMC + b"\r\n") == [GGA, RMC]
    c = framer.counters
    assert (c.frames, c.garbage_bytes, c.garbage_runs, c.overlong) == (2, 0, 0, 0)


def test_a_sentence_split_across_many_feeds_comes_out_whole():
    for size in (1, 2, 3, 7, 64):
        framer = LineFramer()
        assert feed_in_pieces(framer, (GGA + b"\r\n") * 3, size) == [GGA] * 3


def test_the_rest_of_a_sentence_just_begun_is_the_shortest_recent_one_less_what_came():
    """What a driver waits for before its next read (``rest_bytes``): never past the end of
    a sentence as short as the shortest of the last few, its CR included."""
    framer = LineFramer()
    assert framer.feed(GGA[:10]) == [] and framer.rest_bytes() == 0  # no length known yet
    framer = LineFramer()
    framer.feed(GGA + b"\r\n" + RMC + b"\r\n")
    shortest = min(len(GGA), len(RMC))
    assert framer.feed(GGA[:12]) == [] and framer.rest_bytes() == shortest - 12 + 1
    assert framer.feed(GGA[12:20]) == [] and framer.rest_bytes() == 0  # waited for already
    # A chunk that ends one sentence and begins the next: the new one's rest.
    assert framer.feed(GGA[20:] + b"\r\n" + RMC[:5]) == [GGA]
    assert framer.rest_bytes() == shortest - 5 + 1
    assert framer.feed(RMC[5:] + b"\r\n") == [RMC] and framer.rest_bytes() == 0
    framer.feed(b"$" + b"X" * 300 + b"\r\n$GP")  # an over-long line is no sentence's length
    assert framer.rest_bytes() == shortest - 3 + 1


def test_bare_cr_or_lf_endings_work_too():
    assert LineFramer().feed(GGA + b"\n" + RMC + b"\r") == [GGA, RMC]


def test_garbage_between_sentences_is_counted_and_skipped():
    framer = LineFramer()
    out = framer.feed(b"junk" + GGA + b"\r\n\x00\x01more junk\r\n" + RMC + b"\r\n")
    assert out == [GGA, RMC]
    assert framer.counters.garbage_bytes == len(b"junk") + len(b"\x00\x01more junk")
    assert framer.counters.garbage_runs == 2


def test_a_sentence_cut_short_by_the_next_one_is_garbage():
    framer = LineFramer()
    out = framer.feed(GGA[:30] + RMC + b"\r\n")
    assert out == [RMC]
    assert framer.counters.garbage_bytes == 30 and framer.counters.frames == 1


def test_an_over_long_line_is_dropped_counted_and_framing_resumes():
    framer = LineFramer(max_len=100)
    long_line = b"$" + b"A" * 300
    out = feed_in_pieces(framer, long_line + b"\r\n" + GGA + b"\r\n", 16)
    assert out == [GGA]
    assert framer.counters.overlong == 1
    assert framer.counters.garbage_bytes == 0, "the tail of a dropped line is not garbage too"


def test_a_line_of_exactly_max_len_is_kept():
    framer = LineFramer(max_len=len(GGA))
    assert framer.feed(GGA + b"\r\n") == [GGA]
    assert LineFramer(max_len=len(GGA) - 1).feed(GGA + b"\r\n") == []


def test_binary_junk_with_dollars_and_high_bytes_resynchronises():
    framer = LineFramer()
    junk = bytes(range(256)) * 4  # contains '$', CR, LF and every other byte
    out = framer.feed(junk + b"\r\n" + GGA + b"\r\n" + junk[:36] + b"\n" + RMC + b"\n")
    assert out[-2:] == [GGA, RMC]
    assert framer.counters.garbage_bytes > 0


@given(st.binary(max_size=2000), st.integers(min_value=1, max_value=300))
def test_any_byte_stream_never_raises(data, size):
    framer = LineFramer()
    for sentence in feed_in_pieces(framer, data, size):
        assert sentence.startswith(b"$") and len(sentence) <= framer.max_len
        assert not any(b in sentence for b in b"\r\n")


_JUNK = st.binary(max_size=80).map(lambda b: b.replace(b"$", b""))
_SENTENCE = st.text(
    alphabet=st.characters(min_codepoint=0x20, max_codepoint=0x7E, exclude_characters="$"),
    max_size=120,
).map(lambda body: b"$" + body.encode())


@given(st.lists(st.tuples(_JUNK, _SENTENCE), max_size=8), _JUNK, st.integers(1, 50))
def test_every_sentence_embedded_in_junk_comes_out_intact(pairs, tail, size):
    stream = b"".join(junk + sentence + b"\r\n" for junk, sentence in pairs) + tail
    framer = LineFramer()
    assert feed_in_pieces(framer, stream, size) == [sentence for _, sentence in pairs]


def test_bytes_until_counts_the_shortest_recent_sentence_less_what_has_come():
    framer = LineFramer()
    assert framer.bytes_until(2) == 0  # no sentence seen: its length is unknown
    framer.feed(GGA + b"\r\n" + RMC + b"\r\n")
    shortest = min(len(GGA), len(RMC))
    # Each sentence is whole at its line ending's first byte.
    assert framer.bytes_until(1) == shortest + 1
    assert framer.bytes_until(2) == 2 * (shortest + 1)
    assert framer.bytes_until(0) == 0
    framer.feed(GGA[:10])  # a sentence begun: it is the first of those waited for
    assert framer.bytes_until(2) == 2 * (shortest + 1) - 10
