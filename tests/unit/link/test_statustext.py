"""Long status texts go out in chunks that pymavlink's receiver puts back together."""

from __future__ import annotations

from companion.link.codec import new_encoder
from companion.link.statustext import StatusTexts, chunks
from mavlink_dialect import companion as d


def test_a_short_text_is_one_message_with_id_zero():
    texts = StatusTexts(new_encoder(1, 1))
    (msg,) = texts.encode("Return: no home position yet", d.MAV_SEVERITY_WARNING)
    assert (msg.id, msg.chunk_seq) == (0, 0)


def test_a_long_text_comes_back_whole_from_its_chunks():
    long = "DO_REPOSITION: param5 (latitude) 123.5 outside [-90, 90]; " * 3
    texts = StatusTexts(new_encoder(1, 1))
    sent = texts.encode(long, d.MAV_SEVERITY_WARNING)
    assert len(sent) == 4 and {m.id for m in sent} == {1}
    assert [m.chunk_seq for m in sent] == [0, 1, 2, 3]
    receiver = d.MAVLink(None)
    wire = b"".join(m.pack(new_encoder(1, 1)) for m in sent)
    got = receiver.parse_buffer(wire)
    assert "".join(m.text for m in got) == long


def test_a_text_of_exactly_two_fields_ends_with_an_empty_chunk():
    parts = chunks("x" * 100)
    assert [len(p) for p in parts] == [50, 50, 0]
    assert chunks("y" * 50) == [b"y" * 50]
