"""SBUS, the serial protocol of Futaba and FrSky receivers (and of most others as an option).

A frame is 25 bytes: 0x0F; 22 bytes holding 16 channels of 11 bits each, least significant
bit first; a flags byte (bit 0 digital channel 17, bit 1 channel 18, bit 2 frame lost,
bit 3 failsafe; bits 4-7 zero); and an end byte, 0x00 (SBUS2 receivers put telemetry slot
numbers 0x04, 0x14, 0x24, 0x34 there). The line is 100000 baud, 8 data bits, even parity,
2 stop bits, with the signal inverted: a flight computer needs an inverter (or a UART that
inverts its RX) and a UART that takes 100000 baud; a pty takes any framing.

SBUS has no checksum, so a frame is only accepted when its header, flag bits and end byte
are right; anything else is skipped a byte at a time and counted, never raised. Pure: bytes
in, frames out.
"""

from __future__ import annotations

from dataclasses import dataclass

from companion.sensors.frame_scan import FixedFrameScanner

FRAME_LEN = 25
HEADER = 0x0F
END_BYTES = frozenset({0x00, 0x04, 0x14, 0x24, 0x34})
CHANNELS = 16
FLAG_CH17, FLAG_CH18, FLAG_FRAME_LOST, FLAG_FAILSAFE = 1, 2, 4, 8
_UNUSED_FLAGS = 0xF0
RAW_MIN, RAW_MAX = 0, 2047


def raw_to_us(raw: int) -> int:
    """A channel's 11-bit value as a pulse width: 172 → 988 µs, 992 → 1500, 1811 → 2012,
    the scale FrSky and Futaba receivers use (and ArduPilot and PX4 decode)."""
    return round(880 + raw * 0.625)


# Every 11-bit value's pulse, looked up: sixteen channels, fifty frames a second.
_PULSE_US = tuple(raw_to_us(raw) for raw in range(RAW_MAX + 1))


@dataclass(frozen=True)
class SbusFrame:
    """One decoded frame: 16 raw channels (0-2047), the two digital ones and the flags."""

    channels: tuple[int, ...]
    ch17: bool
    ch18: bool
    frame_lost: bool
    failsafe: bool

    def pulses_us(self) -> list[int]:
        """All 18 channels as pulse widths (the digital ones as 1000 or 2000 µs)."""
        digital = [2000 if on else 1000 for on in (self.ch17, self.ch18)]
        return [_PULSE_US[raw] for raw in self.channels] + digital


def decode_frame(frame: bytes) -> SbusFrame | None:
    """One 25-byte frame, or None when it is not one."""
    if len(frame) != FRAME_LEN or frame[0] != HEADER:
        return None
    flags, end = frame[23], frame[24]
    if flags & _UNUSED_FLAGS or end not in END_BYTES:
        return None
    bits = int.from_bytes(frame[1:23], "little")
    channels = tuple((bits >> (11 * i)) & 0x7FF for i in range(CHANNELS))
    return SbusFrame(
        channels,
        bool(flags & FLAG_CH17),
        bool(flags & FLAG_CH18),
        bool(flags & FLAG_FRAME_LOST),
        bool(flags & FLAG_FAILSAFE),
    )


class SbusDecoder:
    """Finds frames in a byte stream, whatever arrives in between."""

    def __init__(self) -> None:
        self._scan = FixedFrameScanner(bytes([HEADER]), FRAME_LEN, decode_frame)
        self.counters = self._scan.counters

    def feed(self, data: bytes) -> list[SbusFrame]:
        """The frames completed by ``data``."""
        return self._scan.feed(data)


class SbusStream:
    """An SBUS line counted as ``companion check`` counts every device's frames."""

    def __init__(self) -> None:
        self.decoder = SbusDecoder()

    def feed(self, data: bytes, t_us: int) -> list[SbusFrame]:
        """The frames completed by ``data`` (an SBUS frame carries no time of its own)."""
        return self.decoder.feed(data)

    @property
    def frames_ok(self) -> int:
        """Frames that passed their check."""
        return self.decoder.counters.ok

    @property
    def frames_bad(self) -> int:
        """Headers whose frame did not pass it."""
        return self.decoder.counters.bad_frames
