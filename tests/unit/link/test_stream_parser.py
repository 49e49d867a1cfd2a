"""The link's MAVLink stream parser: a start byte in garbage costs only itself, so the real
frame behind it is still found (pymavlink's parser swallowed it with the false frame), and
each thrown-away stretch is counted once."""

from __future__ import annotations

import random

from companion.link.codec import dialect as d
from companion.link.codec import new_encoder, new_parser
from companion.link.signing import configure_parser, shared_state, signing_encoder

KEY = bytes(range(32))


def command(gcs, n: int = 0) -> bytes:
    return gcs.command_long_encode(1, 1, d.MAV_CMD_DO_SET_MODE, 0, 1, n, 0, 0, 0, 0, 0).pack(gcs)


def chunked(parser, data: bytes, size: int) -> list:
    """What a serial port delivers: the stream in reads of ``size`` bytes."""
    out: list = []
    for i in range(0, len(data), size):
        out += parser.parse_buffer(data[i : i + size])
    return out


JUNK = (b"\xfd", b"\xfd\x20", b"\xfe\x30", b"ab\xfe\x30xyz", b"\xfd\x00\x00\xfe\xfd")


def test_a_command_behind_start_bytes_in_garbage_is_decoded():
    gcs = new_encoder(255, 190)
    for junk in JUNK:
        parser = new_parser()
        (msg,) = parser.parse_buffer(junk + command(gcs), final=True)
        assert msg.get_type() == "COMMAND_LONG" and msg.command == d.MAV_CMD_DO_SET_MODE
        assert parser.counters.rejected == 1, (junk, parser.counters)
        assert parser.counters.dropped_bytes == len(junk)


def test_on_a_stream_the_command_comes_out_once_the_bytes_a_false_header_claims_arrive():
    gcs = new_encoder(255, 190)
    heartbeat = gcs.heartbeat_encode(6, 8, 0, 0, 4).pack(gcs)
    for junk in JUNK:  # b"\xfe\x30xyz" reads as a 48-byte STATUSTEXT: 56 bytes to wait for
        parser = new_parser()
        got = chunked(parser, junk + command(gcs) + heartbeat, 7)
        assert [m.get_type() for m in got] == ["COMMAND_LONG", "HEARTBEAT"], junk
        assert parser.counters.rejected == 1, (junk, parser.counters)


def test_every_frame_survives_random_garbage_between_frames():
    rng, gcs = random.Random(3), new_encoder(255, 190)
    stream = bytearray()
    for n in range(500):
        stream += rng.randbytes(rng.randint(0, 40)) + rng.choice([b"", b"\xfd", b"\xfe"])
        stream += command(gcs, n)
    parser = new_parser()
    got = chunked(parser, bytes(stream), 64)
    assert [int(m.param2) for m in got] == list(range(500))


def test_a_truncated_frame_running_into_the_next_is_one_rejection():
    gcs = new_encoder(255, 190)
    cut = command(gcs, 1)[:-9]  # its length byte reaches into the frame that follows
    parser = new_parser()
    got = chunked(parser, cut + command(gcs, 2) + cut + command(gcs, 3), 5)
    assert [int(m.param2) for m in got] == [2, 3]
    assert parser.counters.bad_crc == 2 and parser.counters.rejected == 2
    # Two cut frames in a row: the second lies in what the first claimed, so one rejection.
    got = chunked(parser, cut + cut + command(gcs, 4), 5)
    assert [int(m.param2) for m in got] == [4] and parser.counters.rejected == 3


def test_a_corrupted_frame_or_a_garbage_run_counts_once_whatever_start_bytes_it_holds():
    gcs = new_encoder(255, 190)
    broken = bytearray(command(gcs))
    broken[-1] ^= 0xFF
    garbage = b"x" + b"\xfd\xfe" * 40 + b"\x00\xfd"
    parser = new_parser()
    got = parser.parse_buffer(bytes(broken) + command(gcs) + garbage + command(gcs))
    assert len(got) == 2
    assert parser.counters.bad_crc == 1 and parser.counters.garbage == 1
    assert parser.counters.rejected == 2


def test_an_unknown_message_id_or_flag_is_a_false_start():
    gcs = new_encoder(255, 190)
    unknown = b"\xfd\x05\x00\x00\x00\xff\xbe\x99\x99\x99"  # message 0x999999
    flags = b"\xfd\x05\x80\x00\x00\xff\xbe\x00\x00\x00"  # incompat flag 0x80
    parser = new_parser()
    got = parser.parse_buffer(unknown + command(gcs) + flags + command(gcs))
    assert len(got) == 2 and parser.counters.bad_header == 2


def test_a_datagram_that_ends_inside_a_false_frame_still_yields_the_frame_in_it():
    gcs = new_encoder(255, 190)
    parser = new_parser()
    (msg,) = parser.parse_buffer(b"\xfe\xff" + command(gcs), final=True)
    assert msg.get_type() == "COMMAND_LONG"
    assert parser.counters.rejected == 1
    assert parser.parse_buffer(command(gcs)[:20], final=True) == []
    assert parser.counters.truncated == 1 and parser.counters.rejected == 2


def test_mavlink1_frames_are_found_too():
    gcs = new_encoder(255, 190)
    v1 = gcs.heartbeat_encode(6, 8, 0, 0, 4).pack(gcs, force_mavlink1=True)
    parser = new_parser()
    got = chunked(parser, b"\xfe\x09" + v1 + b"\xfd" + v1, 3)
    assert [m.get_type() for m in got] == ["HEARTBEAT", "HEARTBEAT"]


def test_signed_frames_behind_garbage_decode_and_a_bad_signature_is_refused_whole():
    gcs, forger = new_encoder(255, 190), new_encoder(255, 190)
    signing_encoder(gcs, KEY, link_id=1)
    # The same stream: a forged frame's timestamp is not stored (test_signature_replay).
    signing_encoder(forger, bytes(32), link_id=1)
    parser = new_parser()
    configure_parser(parser.mav, shared_state(KEY), "required")
    stream = b"\xfd\x40" + command(gcs, 1) + command(forger, 2) + b"\xfe" + command(gcs, 3)
    got = chunked(parser, stream, 11)
    assert [int(m.param2) for m in got] == [1, 3]
    assert all(m._signed for m in got)
    assert parser.counters.bad_signature == 1 and parser.counters.rejected == 3


def _with_extensions(msg, extra: bytes) -> bytes:
    """``msg`` framed with ``extra`` payload bytes after its own: extension fields of a
    newer definition (the CRC extra covers only the base fields)."""
    gcs = new_encoder(255, 190)
    frame = bytearray(msg.pack(gcs))
    header = 10  # MAVLink 2, unsigned
    whole = type(msg).unpacker.size  # the encoder cut the payload's trailing zeros
    payload = bytes(frame[header:-2]).ljust(whole, b"\0") + extra
    head = bytearray(frame[:header])
    head[1] = len(payload)
    crc = d.x25crc(bytes(head[1:]) + payload + bytes([msg.crc_extra]))
    return bytes(head) + payload + crc.crc.to_bytes(2, "little")


def test_a_mavlink2_message_longer_by_newer_extension_fields_is_read():
    """QGroundControl's MAVLink Console sends SERIAL_CONTROL with its target_system and
    target_component, extension fields the vehicle's definition has not got: 81 bytes
    against 79. It is read (refused as 'longer than the message', the console got nothing);
    the CRC still guards it."""
    gcs = new_encoder(255, 190)
    serial = gcs.serial_control_encode(
        d.SERIAL_CONTROL_DEV_SHELL, 22, 0, 0, 4, list(b"ver\n".ljust(70, b"\0"))
    )
    parser = new_parser()
    msg, after = parser.parse_buffer(_with_extensions(serial, b"\x01\x01") + command(gcs))
    assert after.get_type() == "COMMAND_LONG"
    assert msg.get_type() == "SERIAL_CONTROL" and bytes(msg.data[: msg.count]) == b"ver\n"
    assert parser.counters.rejected == 0
