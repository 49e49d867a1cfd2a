"""The MAVLink dialect the vehicle speaks, imported explicitly (no pymavlink global), and
the parser that finds its frames in a byte stream however much garbage surrounds them."""

from __future__ import annotations

import hashlib
import hmac
import re
from dataclasses import dataclass
from typing import Any

from mavlink_dialect import companion as dialect

__all__ = [
    "MavlinkStream",
    "ParserCounters",
    "SigningMAVLink",
    "StreamParser",
    "dialect",
    "new_encoder",
    "new_parser",
    "signature_verdict",
]

V1, V2 = dialect.PROTOCOL_MARKER_V1, dialect.PROTOCOL_MARKER_V2
HEADER_LEN = {V1: dialect.HEADER_LEN_V1, V2: dialect.HEADER_LEN_V2}  # start byte included
SIGNED = dialect.MAVLINK_IFLAG_SIGNED
SIGNATURE_LEN = dialect.MAVLINK_SIGNATURE_BLOCK_LEN
CRC_LEN = 2
SIGNED_PART = -6  # a signature covers the frame up to its own 6 bytes (timestamp included)
ONE_MINUTE = 6_000_000  # in signing units (10 µs): how far behind ours a timestamp may be
_START = re.compile(b"[\xfd\xfe]")
# A header must name a message we know, and in MAVLink 1 a payload no longer than that
# message's: msgid → (CRC extra, longest payload). An unknown id cannot be checksummed (its
# CRC extra is unknown), so it cannot be told from garbage; the C library (PX4, ArduPilot)
# drops those too, as failing their checksum. A MAVLink 2 payload may be longer: a sender
# with a newer definition adds extension fields (QGroundControl's SERIAL_CONTROL carries
# its target in two), which the CRC extra does not cover and an older reader ignores.
_KNOWN = {i: (cls.crc_extra, cls.unpacker.size) for i, cls in dialect.mavlink_map.items()}


def new_encoder(sysid: int, compid: int = 1) -> Any:
    """A MAVLink 2 encoder for messages from (sysid, compid); it writes nothing itself."""
    mav = dialect.MAVLink(None, srcSystem=sysid, srcComponent=compid)
    return mav


def new_parser() -> StreamParser:
    """A parser for one remote's byte stream: bad bytes become counted rejections."""
    return StreamParser()


@dataclass
class ParserCounters:
    """What a parser kept and threw away; each thrown-away stretch counts once, under the
    reason it began with (a run of garbage that ends in a false start is one rejection)."""

    frames: int = 0  # decoded and accepted
    bad_crc: int = 0  # checksum failed: a corrupted frame, or a start byte in garbage
    bad_header: int = 0  # unknown message id, a payload longer than the message, bad flags
    truncated: int = 0  # still incomplete where its datagram ended
    bad_signature: int = 0  # signed, but not with our key (or unsigned where it must be)
    replayed: int = 0  # well signed, but not newer than its stream's last, or a minute stale
    refused: int = 0  # good checksum, refused all the same: unpacking
    garbage: int = 0  # runs of bytes before any start byte
    dropped_bytes: int = 0  # every byte outside an accepted or refused frame

    @property
    def rejected(self) -> int:
        refused = self.bad_signature + self.replayed + self.refused
        return self.bad_crc + self.bad_header + self.truncated + refused + self.garbage


class SigningMAVLink(dialect.MAVLink):
    """pymavlink's decoder with the signature check in the order the spec and the C library
    use. pymavlink's own ``check_signature`` stores a frame's timestamp as its stream's
    newest before it compares the signature, so one forged frame with a far-future
    timestamp on a real (sysid, compid, link id) made the real sender's frames replays
    from then on. ``verdict`` says why the last signed frame was refused ("" if it was not).
    """

    verdict = ""

    def check_signature(self, msgbuf: bytearray, sysid: int, compid: int) -> bool:
        self.verdict = signature_verdict(self.signing, bytes(msgbuf), sysid, compid)
        return not self.verdict


def signature_verdict(signing: Any, frame: bytes, sysid: int, compid: int) -> str:
    """Check a signed frame against ``signing`` (pymavlink's MAVLinkSigning: key, our
    timestamp, the newest timestamp per stream) and record it only if it passes:
    "bad_signature", "replayed", or "" (accepted; its stream and our timestamp moved on).

    The spec's accept rules: the signature is sha256(key + frame up to it) cut to 6 bytes;
    a stream, (sysid, compid, link id), must never repeat or go back; and no timestamp
    may be more than a minute behind ours, which follows the newest accepted one. The
    spec sets no bound ahead, and after the signature check none is needed: only a key
    holder can move a stream or our timestamp on.
    """
    digest = hashlib.sha256(signing.secret_key + frame[:SIGNED_PART]).digest()
    if not hmac.compare_digest(digest[:6], frame[SIGNED_PART:]):
        return "bad_signature"
    link_id = frame[-SIGNATURE_LEN]
    timestamp = int.from_bytes(frame[-SIGNATURE_LEN + 1 : SIGNED_PART], "little")
    stream = (link_id, sysid, compid)
    last = signing.stream_timestamps.get(stream)
    if (last is not None and timestamp <= last) or timestamp + ONE_MINUTE < signing.timestamp:
        return "replayed"
    signing.stream_timestamps[stream] = timestamp
    signing.timestamp = max(signing.timestamp, timestamp)
    return ""


class StreamParser:
    """MAVLink 1 and 2 frames out of one remote's bytes; nothing in them makes it raise.

    pymavlink's parser trusts the first start byte it meets: a 0xFD in garbage makes it read
    the next byte as a length, take that many bytes (the real frame behind included) and
    throw them all away on the failed checksum. The C library PX4 and ArduPilot use does
    the same, though it refuses bad incompat flags at once. Here a candidate that fails its
    header or checksum costs only its start byte: the search goes on from the next byte, so
    a real frame among the bytes it claimed is still found. A plausible header still waits
    for the bytes it claims, as the C parser does. pymavlink decodes, checksums and checks
    signatures (``self.mav``, where companion.link.signing sets the key and policy), the
    last with our own check (SigningMAVLink).
    """

    def __init__(self) -> None:
        self.mav = SigningMAVLink(None)
        self.counters = ParserCounters()
        self._buf = bytearray()
        self._base = 0  # stream offset of _buf[0]
        self._claim_end = -1  # stream offset the rejection being counted reaches to
        self._claim_frame = False  # and whether a candidate frame (not garbage) set it

    def parse_buffer(self, data: bytes, final: bool = False) -> list[Any]:
        """The messages ``data`` completes. ``final``: nothing follows (a UDP datagram holds
        whole frames), so a frame still incomplete is rejected and its bytes searched now."""
        self._buf += data
        out: list[Any] = []
        pos = self._scan(out, final)
        del self._buf[:pos]
        self._base += pos
        if final:
            self._claim_end = -1  # the next datagram's rejections are its own
        return out

    def _scan(self, out: list[Any], final: bool) -> int:
        """Decode from the start of the buffer; returns how many bytes are done with."""
        buf, pos, n = self._buf, 0, len(self._buf)
        while pos < n:
            if buf[pos] != V2 and buf[pos] != V1:
                found = _START.search(buf, pos)
                end = found.start() if found else n
                self._reject(pos, end - pos, end - pos, "garbage")
                pos = end
                continue
            size, plausible = _frame_size(buf, pos, n)
            if not plausible:
                self._reject(pos, size or 1, 1, "bad_header")
                pos += 1
            elif size is None or pos + size > n:
                if not final:
                    break  # wait for the rest
                self._reject(pos, n - pos if size is None else size, 1, "truncated")
                pos += 1
            else:
                pos += self._take(buf[pos : pos + size], pos, out)
        return pos

    def _take(self, frame: bytearray, pos: int, out: list[Any]) -> int:
        """Decode one candidate frame at ``pos``; returns the bytes it used up."""
        self.mav.verdict, unsigned = "", False
        try:
            msg = self.mav.decode(frame)
        except Exception as exc:  # MAVError mostly, but pymavlink is third-party input handling
            msg, unsigned = None, str(exc) == "Invalid signature"  # unsigned where it must not be
        if msg is not None:
            out.append(msg)
            self.counters.frames += 1
            self._claim_end = -1
            return len(frame)
        if _checksum_ok(frame):  # a real frame, refused whole: signature, payload
            reason = self.mav.verdict or ("bad_signature" if unsigned else "refused")
            setattr(self.counters, reason, getattr(self.counters, reason) + 1)
            self._claim_end = -1
            return len(frame)
        self._reject(pos, len(frame), 1, "bad_crc")
        return 1

    def _reject(self, pos: int, reach: int, dropped: int, reason: str) -> None:
        """Throw away ``dropped`` bytes at ``pos`` (claiming ``reach``); a new rejection
        unless they lie in what the one being counted claimed, or follow its garbage."""
        start, c = self._base + pos, self.counters
        if start > self._claim_end or (start == self._claim_end and self._claim_frame):
            setattr(c, reason, getattr(c, reason) + 1)
        if start + reach > self._claim_end:
            self._claim_end, self._claim_frame = start + reach, reason != "garbage"
        c.dropped_bytes += dropped


def _frame_size(buf: bytearray, pos: int, n: int) -> tuple[int | None, bool]:
    """(Bytes the frame starting at ``pos`` claims, whether its header could begin one);
    (None, True) until the header is complete."""
    header = HEADER_LEN[buf[pos]]
    if n - pos < header:
        return None, True
    length = buf[pos + 1]
    if buf[pos] == V2:
        flags = buf[pos + 2]
        msgid = buf[pos + 7] | buf[pos + 8] << 8 | buf[pos + 9] << 16
        size = header + length + CRC_LEN + (SIGNATURE_LEN if flags & SIGNED else 0)
        if flags & ~SIGNED:
            return size, False
    else:
        msgid = buf[pos + 5]
        size = header + length + CRC_LEN
    known = _KNOWN.get(msgid)
    return size, known is not None and (length <= known[1] or buf[pos] == V2)


def _checksum_ok(frame: bytearray) -> bool:
    """Whether a frame whose header passed carries the checksum of its own bytes."""
    header = HEADER_LEN[frame[0]]
    signed = frame[0] == V2 and frame[2] & SIGNED
    end = len(frame) - CRC_LEN - (SIGNATURE_LEN if signed else 0)
    msgid = frame[7] | frame[8] << 8 | frame[9] << 16 if frame[0] == V2 else frame[5]
    crc = dialect.x25crc(frame[1:end] + bytes([_KNOWN[msgid][0]]))
    return end >= header and crc.crc == int.from_bytes(frame[end : end + CRC_LEN], "little")


class MavlinkStream:
    """A radio's bytes counted as ``companion check`` counts every device's frames: what a
    ground station sends through it, signed or not (the bench has no key to judge by)."""

    def __init__(self) -> None:
        self.parser = StreamParser()

    def feed(self, data: bytes, t_us: int) -> list[object]:
        """The MAVLink messages completed by ``data``."""
        return self.parser.parse_buffer(data)

    @property
    def frames_ok(self) -> int:
        """Messages that passed their checksum."""
        return self.parser.counters.frames

    @property
    def frames_bad(self) -> int:
        """Bad checksums and headers, truncated frames and runs of garbage."""
        return self.parser.counters.rejected
