"""A read-only MAVLink FTP server over an in-memory file table (pure: payload bytes in, out).

It serves what QGroundControl's FTP client asks for when it downloads component metadata:
OpenFileRO, BurstReadFile, ReadFile (to fill gaps), TerminateSession, ResetSessions, and
ListDirectory. Every request is a FILE_TRANSFER_PROTOCOL payload (251 bytes); every reply
echoes the request's opcode in ``req_opcode`` with ``seq_number`` one more than the request's
(bursts count on from there). Anything malformed or unsupported gets a NAK with the protocol's
error code and is counted; nothing a ground station sends raises.

Sessions belong to the station that opened them (its system and component id): a
ResetSessions ends only the asking station's own, and another station's session number
reads as an invalid session, so QGroundControl's metadata download and a script's or
MAVProxy's FTP on a second link never cut each other short.
"""

from __future__ import annotations

import struct
from collections.abc import Mapping
from dataclasses import dataclass, field

PAYLOAD_LEN = 251
# seq, session, opcode, size, req_opcode, burst_complete, padding, offset
HEADER = struct.Struct("<HBBBBBxI")
DATA_MAX = PAYLOAD_LEN - HEADER.size  # 239
MAX_SESSIONS = 4
BURST_PACKETS = 32  # one burst then waits for the client's next request: a radio keeps up

# Opcodes and error codes of the MAVLink FTP specification.
TERMINATE_SESSION, RESET_SESSIONS, LIST_DIRECTORY, OPEN_FILE_RO, READ_FILE = 1, 2, 3, 4, 5
BURST_READ_FILE = 15
ACK, NAK = 128, 129
ERR_INVALID_DATA_SIZE, ERR_INVALID_SESSION = 3, 4
ERR_NO_SESSIONS, ERR_EOF, ERR_UNKNOWN_COMMAND, ERR_FILE_NOT_FOUND = 5, 6, 7, 10


@dataclass(frozen=True)
class Packet:
    """One FTP payload, decoded."""

    seq: int
    session: int
    opcode: int
    size: int
    req_opcode: int
    burst_complete: int
    offset: int
    data: bytes

    def pack(self) -> bytes:
        head = HEADER.pack(
            self.seq & 0xFFFF,
            self.session,
            self.opcode,
            self.size,
            self.req_opcode,
            self.burst_complete,
            self.offset,
        )
        return (head + self.data).ljust(PAYLOAD_LEN, b"\0")


def parse(payload: bytes) -> Packet | None:
    """The packet in a payload, or None when it is too short to hold a header."""
    if len(payload) < HEADER.size:
        return None
    seq, session, opcode, size, req, burst, offset = HEADER.unpack_from(payload)
    return Packet(seq, session, opcode, size, req, burst, offset, bytes(payload[HEADER.size :]))


def _path(request: Packet) -> str:
    """The path a request names: its data up to ``size`` (or the first NUL)."""
    raw = request.data[: request.size].split(b"\0", 1)[0]
    return raw.decode("utf-8", errors="replace").strip("/")


Client = tuple[int, int]  # the requesting station's system and component id


def _entry(rest: str, content: bytes) -> str:
    """A listing's entry for a file ``rest`` below the listed folder: the file itself, or
    the first folder on its way."""
    if "/" in rest:
        return f"D{rest.split('/', 1)[0]}"
    return f"F{rest}\t{len(content)}"


@dataclass
class FtpServer:
    """Read-only sessions over ``files`` (path without leading slash → content)."""

    files: Mapping[str, bytes]
    sessions: dict[int, tuple[Client, str]] = field(default_factory=dict)
    refused: int = 0  # malformed or unsupported requests, answered with a NAK
    _client: Client = field(default=(0, 0), init=False, repr=False)  # the one asking now

    def handle(self, payload: bytes, client: Client = (0, 0)) -> list[bytes]:
        """The reply payloads to one request payload (several for a burst) from ``client``."""
        self._client = client
        request = parse(payload)
        if request is None:
            self.refused += 1
            return []  # no header, no sequence number to answer with
        if request.size > DATA_MAX:
            return [self._nak(request, ERR_INVALID_DATA_SIZE)]
        handler = {
            OPEN_FILE_RO: self._open,
            READ_FILE: self._read,
            BURST_READ_FILE: self._burst,
            TERMINATE_SESSION: self._terminate,
            RESET_SESSIONS: self._reset,
            LIST_DIRECTORY: self._list,
        }.get(request.opcode)
        if handler is None:
            return [self._nak(request, ERR_UNKNOWN_COMMAND)]
        return handler(request)

    def _reply(self, request: Packet, data: bytes = b"", **fields: int) -> bytes:
        values = {"session": request.session, "offset": request.offset, "burst_complete": 0}
        values.update(fields)
        return Packet(
            seq=values.pop("seq", request.seq + 1),
            opcode=values.pop("opcode", ACK),
            size=len(data),
            req_opcode=request.opcode,
            data=data,
            **values,
        ).pack()

    def _nak(self, request: Packet, error: int, **fields: int) -> bytes:
        if error != ERR_EOF:  # reading to the end is how every download ends
            self.refused += 1
        return self._reply(request, bytes([error]), opcode=NAK, **fields)

    def _open(self, request: Packet) -> list[bytes]:
        path = _path(request)
        if path not in self.files:
            return [self._nak(request, ERR_FILE_NOT_FOUND)]
        free = [s for s in range(MAX_SESSIONS) if s not in self.sessions]
        if not free:
            return [self._nak(request, ERR_NO_SESSIONS)]
        self.sessions[free[0]] = (self._client, path)
        size = struct.pack("<I", len(self.files[path]))
        return [self._reply(request, size, session=free[0], offset=0)]

    def _own(self, session: int) -> str | None:
        """The path of ``session`` if the asking station opened it."""
        owner, path = self.sessions.get(session, (None, None))
        return path if owner == self._client else None

    def _content(self, request: Packet) -> bytes | None:
        path = self._own(request.session)
        return None if path is None else self.files[path]

    def _read(self, request: Packet) -> list[bytes]:
        content = self._content(request)
        if content is None:
            return [self._nak(request, ERR_INVALID_SESSION)]
        if request.offset >= len(content):
            return [self._nak(request, ERR_EOF)]
        chunk = content[request.offset : request.offset + min(request.size or DATA_MAX, DATA_MAX)]
        return [self._reply(request, chunk)]

    def _burst(self, request: Packet) -> list[bytes]:
        """Consecutive chunks from ``offset``; the last carries burst_complete or is an EOF NAK."""
        content = self._content(request)
        if content is None:
            return [self._nak(request, ERR_INVALID_SESSION)]
        out, offset, seq = [], request.offset, request.seq + 1
        for n in range(BURST_PACKETS):
            if offset >= len(content):
                out.append(self._nak(request, ERR_EOF, seq=seq, offset=offset))
                break
            chunk = content[offset : offset + DATA_MAX]
            last = n == BURST_PACKETS - 1
            out.append(self._reply(request, chunk, seq=seq, offset=offset, burst_complete=last))
            offset, seq = offset + len(chunk), seq + 1
        return out

    def _terminate(self, request: Packet) -> list[bytes]:
        if self._own(request.session) is None:
            return [self._nak(request, ERR_INVALID_SESSION)]
        del self.sessions[request.session]
        return [self._reply(request)]

    def _reset(self, request: Packet) -> list[bytes]:
        for session in [s for s, (owner, _) in self.sessions.items() if owner == self._client]:
            del self.sessions[session]
        return [self._reply(request)]

    def _list(self, request: Packet) -> list[bytes]:
        """Entries ``F<name>\\t<size>`` and ``D<name>`` (a folder on the way to a file: MAVSDK's
        ftp_list_dir.py lists "/" and found nothing while every file sat in metadata/),
        NUL-separated, from entry number ``offset``."""
        folder = _path(request)
        prefix = f"{folder}/" if folder else ""
        entries = sorted({_entry(p[len(prefix) :], self.files[p]) for p in self.files
                          if p.startswith(prefix)})  # fmt: skip
        if not entries and folder:
            return [self._nak(request, ERR_FILE_NOT_FOUND)]
        data = b""
        for text in entries[request.offset :]:
            entry = text.encode() + b"\0"
            if len(data) + len(entry) > DATA_MAX:
                break
            data += entry
        if not data:
            return [self._nak(request, ERR_EOF)]
        return [self._reply(request, data)]
