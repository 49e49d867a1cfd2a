"""The read-only MAVLink FTP server: downloads the way QGroundControl makes them, and garbage."""

from __future__ import annotations

import json
import struct

from hypothesis import given, settings
from hypothesis import strategies as st

from companion.link.ftp import (
    ACK,
    BURST_PACKETS,
    BURST_READ_FILE,
    DATA_MAX,
    ERR_EOF,
    ERR_INVALID_DATA_SIZE,
    ERR_INVALID_SESSION,
    ERR_NO_SESSIONS,
    LIST_DIRECTORY,
    MAX_SESSIONS,
    NAK,
    OPEN_FILE_RO,
    PAYLOAD_LEN,
    READ_FILE,
    RESET_SESSIONS,
    TERMINATE_SESSION,
    FtpServer,
    Packet,
    parse,
)
from companion.params import ParamDecl
from companion.params.metadata import crc32, metadata_files

BIG = bytes(range(256)) * 40  # 10 240 bytes: more than one burst of 32 × 239


def ask(server: FtpServer, opcode: int, seq: int = 1, **fields) -> list[Packet]:
    data = fields.pop("data", b"")
    values = {"session": 0, "offset": 0, "size": len(data)} | fields
    raw = Packet(seq, values["session"], opcode, values["size"], 0, 0, values["offset"], data)
    return [parse(r) for r in server.handle(raw.pack())]


def test_burst_download_gives_the_file_with_qgc_sequence_numbers():
    server = FtpServer({"a/big.bin": BIG})
    (opened,) = ask(server, OPEN_FILE_RO, data=b"/a/big.bin")
    assert opened.opcode == ACK and struct.unpack("<I", opened.data[:4])[0] == len(BIG)
    content, offset, seq, bursts = bytearray(), 0, 3, 0
    while True:
        replies = ask(server, BURST_READ_FILE, seq, session=opened.session, offset=offset)
        bursts += 1
        assert [r.seq for r in replies] == list(range(seq + 1, seq + 1 + len(replies)))
        assert all(r.req_opcode == BURST_READ_FILE for r in replies)
        for r in replies:
            if r.opcode == NAK:
                assert r.data[0] == ERR_EOF and r is replies[-1]
                break
            content += r.data[: r.size]
            offset = r.offset + r.size
        if replies[-1].opcode == NAK:
            break
        assert replies[-1].burst_complete and len(replies) == BURST_PACKETS
        seq = replies[-1].seq + 1
    assert bytes(content) == BIG and bursts == 2
    assert server.refused == 0  # the EOF that ends a download is no refusal


def test_read_file_fills_a_gap_and_terminate_ends_the_session():
    server = FtpServer({"f": BIG})
    (opened,) = ask(server, OPEN_FILE_RO, data=b"f")
    (chunk,) = ask(server, READ_FILE, session=opened.session, offset=1000, size=DATA_MAX)
    assert chunk.data[: chunk.size] == BIG[1000 : 1000 + DATA_MAX]
    (done,) = ask(server, TERMINATE_SESSION, session=opened.session)
    assert done.opcode == ACK
    (late,) = ask(server, READ_FILE, session=opened.session, size=10)
    assert late.opcode == NAK and server.refused == 1


def test_sessions_run_out_and_list_directory_names_the_files():
    server = FtpServer({"m/g.json": b"{}", "m/p.json": b"[]"})
    for _ in range(MAX_SESSIONS):
        assert ask(server, OPEN_FILE_RO, data=b"m/g.json")[0].opcode == ACK
    (full,) = ask(server, OPEN_FILE_RO, data=b"m/g.json")
    assert (full.opcode, full.data[0]) == (NAK, ERR_NO_SESSIONS)
    (listing,) = ask(server, LIST_DIRECTORY, data=b"/m")
    assert listing.data[: listing.size].split(b"\0")[:2] == [b"Fg.json\t2", b"Fp.json\t2"]
    (root,) = ask(server, LIST_DIRECTORY, data=b"/")  # the folder on the way to the files
    assert root.data[: root.size].split(b"\0")[:1] == [b"Dm"]


@settings(max_examples=400, deadline=None)
@given(st.binary(max_size=PAYLOAD_LEN + 20))
def test_any_payload_gets_a_reply_or_a_count_never_an_exception(payload):
    server = FtpServer({"m/g.json": b"{}"})
    replies = server.handle(payload)
    assert all(len(r) == PAYLOAD_LEN for r in replies)
    for raw in replies:
        reply = parse(raw)
        assert reply.opcode in (ACK, NAK) and reply.size <= DATA_MAX
    if any(parse(r).opcode == NAK and parse(r).data[0] != ERR_EOF for r in replies):
        assert server.refused >= 1
    if len(payload) < 12:
        assert replies == [] and server.refused == 1


def test_an_oversized_size_field_is_refused():
    server = FtpServer({"f": b"x"})
    (reply,) = ask(server, OPEN_FILE_RO, size=240, data=b"f")
    assert (reply.opcode, reply.data[0]) == (NAK, ERR_INVALID_DATA_SIZE)


def test_metadata_files_follow_the_declarations_in_qgc_schema():
    decls = [
        ParamDecl("FS_GPS_LOST_S", 3.0, 0.5, 60.0, "s", "GPS silence before failsafe"),
        ParamDecl("BATT_CAPACITY", 2200.0, 0.0, unit="mAh", doc="capacity", reboot_required=True),
    ]
    meta = metadata_files(decls)
    general = json.loads(meta.files["metadata/general.json"])
    assert meta.general_crc == crc32(meta.files["metadata/general.json"])
    (entry,) = general["metadataTypes"]
    params_raw = meta.files[entry["uri"].removeprefix("mftp://")]
    assert entry["fileCrc"] == crc32(params_raw)
    params = {p["name"]: p for p in json.loads(params_raw)["parameters"]}
    assert params["FS_GPS_LOST_S"] | {} == {
        "name": "FS_GPS_LOST_S", "type": "Float", "shortDesc": "GPS silence before failsafe",
        "units": "s", "default": 3.0, "min": 0.5, "max": 60.0, "group": "FS",
        "rebootRequired": False,
    }  # fmt: skip
    batt = params["BATT_CAPACITY"]
    assert batt["rebootRequired"] is True and "max" not in batt  # no infinity in JSON


QGC, SCRIPT = (255, 190), (254, 191)


def test_a_station_resetting_its_sessions_leaves_another_stations_download_going():
    server = FtpServer({"a/big.bin": BIG, "b.txt": b"hello"})
    open_qgc = Packet(1, 0, OPEN_FILE_RO, 9, 0, 0, 0, b"a/big.bin").pack()
    (opened,) = [parse(r) for r in server.handle(open_qgc, QGC)]
    reset = Packet(1, 0, RESET_SESSIONS, 0, 0, 0, 0, b"").pack()
    (reset_ack,) = [parse(r) for r in server.handle(reset, SCRIPT)]
    assert reset_ack.opcode == ACK
    read = Packet(3, opened.session, READ_FILE, DATA_MAX, 0, 0, 0, b"").pack()
    (chunk,) = [parse(r) for r in server.handle(read, QGC)]
    assert chunk.opcode == ACK and chunk.data[: chunk.size] == BIG[:DATA_MAX]
    # The station's own reset does end it.
    server.handle(reset, QGC)
    (gone,) = [parse(r) for r in server.handle(read, QGC)]
    assert gone.opcode == NAK and gone.data[0] == ERR_INVALID_SESSION


def test_another_stations_session_number_is_an_invalid_session_to_read_or_end():
    server = FtpServer({"b.txt": b"hello"})
    open_script = Packet(1, 0, OPEN_FILE_RO, 5, 0, 0, 0, b"b.txt").pack()
    (opened,) = [parse(r) for r in server.handle(open_script, SCRIPT)]
    for opcode in (READ_FILE, BURST_READ_FILE, TERMINATE_SESSION):
        raw = Packet(2, opened.session, opcode, 0, 0, 0, 0, b"").pack()
        (reply,) = [parse(r) for r in server.handle(raw, QGC)]
        assert reply.opcode == NAK and reply.data[0] == ERR_INVALID_SESSION
    # Still the script's: it reads and ends it.
    raw = Packet(3, opened.session, READ_FILE, 0, 0, 0, 0, b"").pack()
    (reply,) = [parse(r) for r in server.handle(raw, SCRIPT)]
    assert reply.opcode == ACK and reply.data[: reply.size] == b"hello"
    raw = Packet(4, opened.session, TERMINATE_SESSION, 0, 0, 0, 0, b"").pack()
    assert parse(server.handle(raw, SCRIPT)[0]).opcode == ACK
