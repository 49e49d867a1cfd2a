"""SBUS frames as a receiver sends them, packed one bit at a time (not the vehicle's way)."""

from __future__ import annotations


def frame(channels: list[int], flags: int = 0, end: int = 0x00) -> bytes:
    """A frame packed one bit at a time, least significant bit of channel 1 first."""
    bits = []
    for value in channels:
        bits += [(value >> b) & 1 for b in range(11)]
    data = bytearray(22)
    for i, bit in enumerate(bits):
        data[i // 8] |= bit << (i % 8)
    return bytes([0x0F, *data, flags, end])


def us_to_raw(us: int) -> int:
    """A pulse width as the 11-bit value FrSky receivers send (988-2012 µs is 172-1811)."""
    return round(172 + (us - 988) * 1639 / 1024)
