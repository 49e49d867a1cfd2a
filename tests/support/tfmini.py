"""A TFmini frame written from Benewake's manual, byte by byte, not with the vehicle's codec."""

from __future__ import annotations

import struct


def frame(dist_cm: int, strength: int = 2000, temp_raw: int = 2248) -> bytes:
    """0x59 0x59, distance and strength (uint16 little-endian), temperature (raw / 8 - 256
    °C: 2248 is 25 °C), and the low byte of the sum of those eight bytes."""
    body = b"YY" + struct.pack("<HHH", dist_cm & 0xFFFF, strength & 0xFFFF, temp_raw & 0xFFFF)
    return body + bytes([sum(body) % 256])
