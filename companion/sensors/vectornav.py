"""VectorNav VN-100/VN-200 ASCII output (``$VNYMR``, ``$VNIMU``) into bus messages.

- ``$VNYMR,yaw,pitch,roll,magX,magY,magZ,accX,accY,accZ,gyroX,gyroY,gyroZ*cs``:
  attitude in degrees, compensated magnetic field in gauss, acceleration in m/s²,
  angular rate in rad/s (register 27).
- ``$VNIMU,magX,magY,magZ,accX,accY,accZ,gyroX,gyroY,gyroZ,temp,pressure*cs``: the
  calibrated but uncompensated sensor values, temperature in °C, pressure in kPa
  (register 54).
- The sensor may append a counter (``,T1162704``) or status field (``,S…``) before the
  checksum (SerialCount/SerialStatus); they are accepted and ignored.
- Checksum: two hex digits are VectorNav's 8-bit XOR of the characters between ``$`` and
  ``*`` (as in NMEA); four are its 16-bit CRC over the same characters, CRC16-CCITT with
  polynomial 0x1021 and initial value 0 (the manual's C routine; the XMODEM variant, which
  is ``binascii.crc_hqx(data, 0)``). ``*XX`` / ``*XXXX``, the placeholders VectorNav
  accepts when checksums are off, are counted as bad checksums: we cannot trust them.

Axes: the sensor's body frame is x forward, y right, z down, and the accelerometer gives
specific force: the manual's example response for a level, still sensor (pitch 0.02°,
roll -1.95°) reads ``+00.005,+00.344,-09.758``. That is exactly ``messages.Imu``'s
convention (level and still: az ≈ -9.81), so values pass through unchanged.
Pure: no port, no clock; ``decode`` never raises.
"""

from __future__ import annotations

import binascii
import ctypes
import math
import re
import struct
from dataclasses import dataclass
from typing import NamedTuple

from companion.messages import Imu, Magnetometer
from companion.sensors.ascii_sentence import sentence_text, xor8

# One way only to match a run of digits (the dot required before a second run): with
# ``\d+\.?\d*`` a run could be split anywhere, and a sentence of long digit runs with a
# right checksum and one bad field took the full match 0.2 s at 72 characters, doubling
# with every few more (the IMU's thread stalled as long).
_NUMBER = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?"
_APPENDED = r"[TS][0-9A-Fa-f]+"  # SerialCount / SerialStatus fields
_HEADER = re.compile(r"VN[A-Z]{3}")
_HEX = frozenset("0123456789abcdefABCDEF")
_FIELD_COUNTS = {"VNYMR": 12, "VNIMU": 11}
# A sentence's fields after its header, in one match (neither pattern holds a comma, so
# this is the same as every field on its own): ``count`` numbers, then appended fields.
_FIELDS = {
    header: re.compile(f"(?:,{_NUMBER}){{{count}}}(?:,{_APPENDED})*")
    for header, count in _FIELD_COUNTS.items()
}
_PLACEHOLDERS = ("XX", "XXXX")
_NUMBER_TEXT = "0123456789+-.eE,"  # every character of ``_NUMBER`` fields and their commas
# Each two-digit checksum as it may be written (either case), and its value: one look-up
# where the usual sentence took an upper(), a set test and an int() (the placeholder "XX"
# is no entry; neither is anything else but two hex digits).
_HEX2 = {a + b: int(a + b, 16) for a in _HEX for b in _HEX}
# The messages made in one call from their fields' bytes: a ctypes structure given its
# fields as arguments sets them one by one (about twice the cost, at every sample). The
# same native layout, so the same bytes: an int64 then doubles, as the classes declare.
_IMU_PACK = struct.Struct("=q7d")
_MAG_PACK = struct.Struct("=q3d")
assert _IMU_PACK.size == ctypes.sizeof(Imu) and _MAG_PACK.size == ctypes.sizeof(Magnetometer)
_imu_from = Imu.from_buffer_copy
_mag_from = Magnetometer.from_buffer_copy


@dataclass
class VectorNavCounters:
    """What the decoder has seen since it was made."""

    ok: int = 0
    bad_checksum: int = 0  # wrong, or a checksum placeholder
    garbage: int = 0  # not a VectorNav sentence, truncated, or bad fields
    ignored: int = 0  # valid VectorNav sentences we do not use ($VNYPR, $VNRRG …)


@dataclass(frozen=True)
class Attitude:
    """The sensor's own attitude estimate (``$VNYMR``), radians."""

    yaw_rad: float  # [-π, π] from north
    pitch_rad: float
    roll_rad: float


class VectorNavReading(NamedTuple):
    """One sentence: IMU and magnetometer, plus what that sentence adds.

    A named tuple, not a frozen dataclass: as immutable, made in a fifth of the time (a
    frozen dataclass sets each field through ``object.__setattr__``), 100 times a second.
    """

    imu: Imu
    mag: Magnetometer
    attitude: Attitude | None  # $VNYMR only
    pressure_pa: float  # $VNIMU only, NaN otherwise


def crc16(payload: str) -> int:
    """VectorNav's 16-bit CRC (CCITT polynomial 0x1021, initial value 0)."""
    return binascii.crc_hqx(payload.encode("ascii"), 0)


class VectorNavDecoder:
    """ASCII sentences into readings; rejects are counted, never raised."""

    def __init__(self) -> None:
        self.counters = VectorNavCounters()

    def decode(self, sentence: bytes | str, t_us: int) -> VectorNavReading | None:
        """One sentence (line ending optional) received at ``t_us``."""
        fields = self._checked_fields(sentence)
        if fields is None:
            return None
        payload, header = fields
        count = _FIELD_COUNTS.get(header)
        if count is None:
            self.counters.ignored += 1
            return None
        numbers = _numbers(header, payload, count)
        if numbers is None or not _angles_in_range(header, numbers):
            self.counters.garbage += 1
            return None
        self.counters.ok += 1
        return _reading(header, numbers, t_us)

    def _checked_fields(self, sentence: bytes | str) -> tuple[str, str] | None:
        """The payload (between ``$`` and ``*``) and header of a whole VectorNav sentence
        whose checksum is right."""
        text = sentence_text(sentence)
        payload, star, given = text[1:].rpartition("*")
        comma = payload.find(",")
        header = payload if comma < 0 else payload[:comma]
        # A header we decode is one the pattern takes, without asking the pattern.
        named = header in _FIELD_COUNTS or _HEADER.fullmatch(header)
        if not (text.startswith("$") and text.isascii() and star and named):
            self.counters.garbage += 1
            return None
        if (value := _HEX2.get(given)) is not None:  # the usual two hex digits
            expected = xor8(payload)
        elif given.upper() in _PLACEHOLDERS:
            self.counters.bad_checksum += 1
            return None
        elif len(given) != 4 or not _HEX.issuperset(given):
            self.counters.garbage += 1
            return None
        else:
            value, expected = int(given, 16), crc16(payload)
        if value != expected:
            self.counters.bad_checksum += 1
            return None
        return payload, header


def _numbers(header: str, payload: str, count: int) -> list[float] | None:
    """The first ``count`` fields after the header as finite numbers; only appended T/S
    fields may follow."""
    values = payload.split(",")[1:]
    # The usual sentence, ``count`` fields of number characters only, skips the pattern:
    # float()'s grammar over those characters is ``_NUMBER``, so a field float() takes
    # is one the pattern takes, and one it refuses, the pattern refuses too.
    if len(values) == count and not payload[len(header) + 1 :].strip(_NUMBER_TEXT):
        try:
            numbers = list(map(float, values))
        except ValueError:
            return None
    elif _FIELDS[header].fullmatch(payload, len(header)):  # appended fields, or garbage
        numbers = list(map(float, values[:count]))
    else:
        return None
    return numbers if all(map(math.isfinite, numbers)) else None


def _angles_in_range(header: str, numbers: list[float]) -> bool:
    if header != "VNYMR":
        return True
    yaw, pitch, roll = numbers[:3]
    return abs(yaw) <= 180.0 and abs(pitch) <= 90.0 and abs(roll) <= 180.0


def _reading(header: str, numbers: list[float], t_us: int) -> VectorNavReading:
    if header == "VNYMR":
        yaw, pitch, roll, *rest = numbers
        attitude = Attitude(math.radians(yaw), math.radians(pitch), math.radians(roll))
        temp_c = pressure_pa = math.nan
    else:
        *rest, temp_c, pressure_kpa = numbers
        attitude, pressure_pa = None, pressure_kpa * 1000.0
    mx, my, mz, ax, ay, az, gx, gy, gz = rest
    imu = _imu_from(_IMU_PACK.pack(t_us, ax, ay, az, gx, gy, gz, temp_c))
    mag = _mag_from(_MAG_PACK.pack(t_us, mx, my, mz))
    return VectorNavReading(imu, mag, attitude, pressure_pa)
