"""Benewake TFmini / TFmini-S / TFmini Plus / TF02 lidar rangefinders: their serial frame.

At 115200 baud 8N1 the device sends, 100 times a second by default, a 9-byte frame::

    0x59 0x59  dist_L dist_H  strength_L strength_H  byte6 byte7  checksum

distance in centimetres and signal strength, both little-endian; byte 6 and 7 are the
temperature (TFmini-S, TFmini Plus: °C = raw / 8 - 256) or the distance mode and a
reserved byte (the first TFmini); the checksum is the low byte of the sum of the first
eight bytes. Distance and strength are what a landing needs, so only they are decoded.

A reading the device itself calls unreliable is kept and flagged, not dropped: a distance
of 0 or above 32767 (the TFmini-S's -1, -2, -4 error codes), a strength below 100 or of
65535 (the manuals' "unreliable" and "overexposed" thresholds), or a distance outside the
range the vehicle was told the part measures. Anything that is not a frame is skipped a
byte at a time and counted, never raised. Pure: bytes in, frames and readings out.
"""

from __future__ import annotations

from dataclasses import dataclass

from companion.sensors.frame_scan import FixedFrameScanner

FRAME_LEN = 9
HEADER = b"\x59\x59"
ERROR_DIST_CM = 0x8000  # and above: the TFmini-S's negative error codes as uint16
WEAK_STRENGTH = 100
SATURATED_STRENGTH = 0xFFFF


def checksum(first_eight: bytes) -> int:
    """The frame's last byte: the low byte of the sum of the eight before it."""
    return sum(first_eight) & 0xFF


def _checked(frame: bytes) -> bytes | None:
    return frame if checksum(frame[:8]) == frame[8] else None


class TfminiFramer:
    """Finds checked 9-byte frames in a byte stream, whatever arrives in between (a
    strength of 0x5959 looks like a header: a frame that does not add up costs one byte)."""

    def __init__(self) -> None:
        self._scan = FixedFrameScanner(HEADER, FRAME_LEN, _checked)
        self.counters = self._scan.counters

    @property
    def rejected(self) -> int:
        """Frames refused by their checksum (garbage bytes are counted apart)."""
        return self.counters.bad_frames

    def feed(self, data: bytes) -> list[bytes]:
        """The whole frames completed by ``data``, their checksums right."""
        return self._scan.feed(data)

    def rest_bytes(self) -> int:
        """None to wait for: a 9-byte frame is on the line for less than a millisecond at
        the sensor's 115200 baud, shorter than any wait would be."""
        return 0


@dataclass(frozen=True)
class RangeSample:
    """One decoded frame: the distance along the beam and whether it can be trusted."""

    t_us: int
    distance_m: float
    strength: int
    valid: bool


@dataclass
class TfminiCounters:
    ok: int = 0  # frames decoded, valid or not
    bad_checksum: int = 0
    garbage: int = 0  # not a frame at all
    out_of_range: int = 0  # decoded, flagged invalid


class TfminiDecoder:
    """Frames into readings, judged against the range the part measures (metres)."""

    def __init__(self, min_m: float = 0.1, max_m: float = 12.0) -> None:
        self.min_m, self.max_m = min_m, max_m
        self.counters = TfminiCounters()

    def decode(self, frame: bytes, t_us: int) -> RangeSample | None:
        """The reading in one frame; None (counted) when it is not a checked frame."""
        if len(frame) != FRAME_LEN or not frame.startswith(HEADER):
            self.counters.garbage += 1
            return None
        if checksum(frame[:8]) != frame[8]:
            self.counters.bad_checksum += 1
            return None
        dist_cm = int.from_bytes(frame[2:4], "little")
        strength = int.from_bytes(frame[4:6], "little")
        distance_m = dist_cm / 100.0
        valid = (
            0 < dist_cm < ERROR_DIST_CM
            and WEAK_STRENGTH <= strength < SATURATED_STRENGTH
            and self.min_m <= distance_m <= self.max_m
        )
        self.counters.ok += 1
        if not valid:
            self.counters.out_of_range += 1
        return RangeSample(t_us, distance_m if dist_cm < ERROR_DIST_CM else -1.0, strength, valid)


def signal_quality(sample: RangeSample) -> int:
    """MAVLink DISTANCE_SENSOR's signal_quality: 1 for an invalid reading, else 2-100 %
    with the strength (1000 and more, as a TFmini reads off grass in daylight, is 100)."""
    if not sample.valid:
        return 1
    return max(2, min(100, sample.strength // 10))
