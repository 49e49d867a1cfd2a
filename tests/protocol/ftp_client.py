"""A MAVLink FTP download as QGroundControl's FTPManager does it, over a pymavlink peer.

OpenFileRO, then BurstReadFile until an EOF NAK (a new burst after each burst_complete),
gaps filled with ReadFile, then ResetSessions. Sequence numbers as QGroundControl keeps them:
a request carries one past the last reply, its reply one more.
"""

from __future__ import annotations

import struct
import time
from typing import Any

HEADER = struct.Struct("<HBBBBBxI")
OPEN_FILE_RO, READ_FILE, RESET_SESSIONS, BURST_READ_FILE = 4, 5, 2, 15
ACK, NAK, ERR_EOF = 128, 129, 6


def request(seq: int, opcode: int, session: int = 0, offset: int = 0, data: bytes = b"") -> bytes:
    head = HEADER.pack(seq, session, opcode, len(data), 0, 0, offset)
    return (head + data).ljust(251, b"\0")


def decode(msg: Any) -> tuple[int, int, int, int, int, int, int, bytes]:
    raw = bytes(msg.payload)
    seq, session, opcode, size, req, burst, offset = HEADER.unpack_from(raw)
    return seq, session, opcode, size, req, burst, offset, raw[12 : 12 + size]


class FtpDownload:
    """One file from the vehicle (sysid 1, compid 1), QGroundControl's way (its FTP
    timeout is 1 s; a busy test machine gets more)."""

    def __init__(self, gcs: Any, timeout_s: float = 3.0) -> None:
        self.gcs = gcs
        self.timeout_s = timeout_s
        self.expected = 0  # the sequence number of the next reply
        self.sysid = gcs.mav.srcSystem  # replies to another station are not this one's

    def send(self, opcode: int, **fields: Any) -> None:
        payload = request(self.expected + 1, opcode, **fields)
        self.expected += 2
        self.gcs.mav.file_transfer_protocol_send(0, 1, 1, payload)

    def reply(self, opcode: int) -> tuple[int, int, int, int, int, int, int, bytes]:
        """The next reply to ``opcode`` (other FTP traffic is not for this step)."""
        deadline = time.monotonic() + self.timeout_s
        while time.monotonic() < deadline:
            conn = self.gcs.conn
            msg = conn.recv_match(type="FILE_TRANSFER_PROTOCOL", blocking=True, timeout=0.2)
            if msg is None or msg.get_srcComponent() != 1 or msg.target_system != self.sysid:
                continue
            fields = decode(msg)
            if fields[4] == opcode:
                return fields
        raise AssertionError(f"no FTP reply to opcode {opcode} within {self.timeout_s} s")

    def get(self, path: str) -> bytes:
        self.send(OPEN_FILE_RO, data=path.encode())
        _, session, op, size, _, _, _, data = self.reply(OPEN_FILE_RO)
        assert op == ACK and size == 4, f"OpenFileRO {path}: NAK {data!r}"
        length = struct.unpack("<I", data)[0]
        content = bytearray(length)
        got = self._burst(session, content)
        for offset in range(0, length, 239):  # fill what the bursts lost, as QGC does
            if not all(got[offset : offset + 239]):
                self.send(READ_FILE, session=session, offset=offset, data=b"\0" * 239)
                _, _, op, size, _, _, at, data = self.reply(READ_FILE)
                assert op == ACK and at == offset
                content[at : at + size] = data
        self.send(RESET_SESSIONS)
        assert self.reply(RESET_SESSIONS)[2] == ACK
        return bytes(content)

    def _burst(self, session: int, content: bytearray) -> list[bool]:
        got = [False] * len(content)
        offset, tries = 0, 0
        while True:
            self.send(BURST_READ_FILE, session=session, offset=offset, data=b"\0" * 239)
            try:
                while True:
                    seq, _, op, size, _, burst, at, data = self.reply(BURST_READ_FILE)
                    if op == NAK:
                        assert data[:1] == bytes([ERR_EOF]), f"burst NAK {data!r}"
                        if seq == self.expected:
                            return got
                        break  # an EOF out of sequence: QGroundControl asks again
                    content[at : at + size] = data
                    got[at : at + size] = [True] * size
                    offset = at + size
                    self.expected = seq + 1
                    if burst:
                        self.expected = seq
                        break
                tries = 0
            except AssertionError:  # no reply in time: QGroundControl retries, same sequence
                tries += 1
                assert tries <= 3, "burst read: no answer after 3 retries"
                self.expected -= 2
