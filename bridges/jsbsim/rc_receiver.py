"""The emulated RC receiver: a scripted pilot's sticks as SBUS frames on a pty.

The pilot is a CSV schedule by simulation time, each row holding until the next:
``t,roll,pitch,yaw,throttle,switch,signal`` with roll, pitch (+ stick back, nose up) and yaw
in [-1, 1], throttle in [0, 1], ``switch`` the mode switch position 1..6 (FLTMODE1..6;
a three-position switch gives 1, 4 and 6) and ``signal`` ``ok``, ``silent`` (the receiver
sends nothing: out of range, unplugged) or ``failsafe`` (it sends its failsafe positions
with the failsafe flag, as FrSky receivers do). Columns left out keep these defaults:
sticks centred, throttle closed, switch 1, signal ok. Without a script the pilot keeps
hands off and the switch where it is, so the vehicle's modes are the ground station's.

The transmitter's channel order is AETR (1 roll, 2 pitch, 3 throttle, 4 yaw) with the mode
switch on 8, as ArduPilot's defaults expect; sticks span 1100-1900 µs (a Futaba-style
transmitter at ±100 %, which ArduPilot's default RCn_MIN/MAX match). The frame is written
from the SBUS description here (11-bit channels least significant bit first, 988-2012 µs
as 172-1811), not with the vehicle's decoder.
"""

from __future__ import annotations

import bisect
import csv
from dataclasses import dataclass
from pathlib import Path

SIGNALS = ("ok", "silent", "failsafe")
SWITCH_US = (1100, 1295, 1425, 1555, 1685, 1900)  # the middle of each of ArduPilot's bands
FAILSAFE_THROTTLE_US = 900  # below THR_FS_VALUE, as ArduPilot asks receivers to be set
SBUS_FAILSAFE_FLAG = 0x08


@dataclass(frozen=True)
class PilotRow:
    """What the pilot holds from ``t_s`` on."""

    t_s: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0
    throttle: float = 0.0
    switch: int = 1
    signal: str = "ok"

    def pulses_us(self) -> list[int]:
        """The transmitter's 16 channels."""
        out = [1500] * 16

        def stick(v: float) -> int:
            return round(1500 + 400 * max(-1.0, min(1.0, v)))

        out[0], out[1], out[3] = stick(self.roll), stick(self.pitch), stick(self.yaw)
        out[2] = round(1100 + 800 * max(0.0, min(1.0, self.throttle)))
        out[7] = SWITCH_US[max(1, min(6, self.switch)) - 1]
        return out


def load_pilot(path: str | Path) -> list[PilotRow]:
    """The schedule, sorted by time; ValueError names the bad row."""
    rows = []
    with Path(path).open(newline="") as f:
        for n, raw in enumerate(csv.DictReader(f), start=2):
            try:
                row = _row(raw)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"{path}:{n}: {exc}") from None
            rows.append(row)
    return sorted(rows, key=lambda r: r.t_s)


def _row(raw: dict[str, str]) -> PilotRow:
    given = {k.strip(): v.strip() for k, v in raw.items() if k and v and v.strip()}
    row = PilotRow(
        t_s=float(given["t"]),
        roll=float(given.get("roll", 0.0)),
        pitch=float(given.get("pitch", 0.0)),
        yaw=float(given.get("yaw", 0.0)),
        throttle=float(given.get("throttle", 0.0)),
        switch=int(given.get("switch", 1)),
        signal=given.get("signal", "ok"),
    )
    if row.signal not in SIGNALS or not 1 <= row.switch <= 6:
        raise ValueError(f"signal must be one of {SIGNALS} and switch 1..6")
    return row


def sbus_frame(pulses_us: list[int], flags: int = 0) -> bytes:
    """One SBUS frame for 16 pulse widths."""
    packed = 0
    for i, us in enumerate(pulses_us[:16]):
        raw = round(172 + (us - 988) * (1811 - 172) / (2012 - 988))
        packed |= (max(0, min(2047, raw)) & 0x7FF) << (11 * i)
    return bytes([0x0F]) + packed.to_bytes(22, "little") + bytes([flags, 0x00])


class EmulatedReceiver:
    """Decides when the receiver sends a frame, and which."""

    def __init__(self, rows: list[PilotRow] | None, rate_hz: float) -> None:
        self.rows = rows or [PilotRow()]
        self.times = [r.t_s for r in self.rows]
        self.period_s = 1.0 / rate_hz
        self.next_s = 0.0

    def now(self, t_s: float) -> PilotRow:
        """The row in force at ``t_s`` (the first row before it starts)."""
        return self.rows[max(0, bisect.bisect_right(self.times, t_s + 1e-9) - 1)]

    def due(self, t_s: float) -> bytes | None:
        """The frame sent at ``t_s``, if one is due and the receiver is not silent."""
        if t_s + 1e-9 < self.next_s:
            return None
        self.next_s += self.period_s
        row = self.now(t_s)
        if row.signal == "silent":
            return None
        if row.signal == "failsafe":
            pulses = row.pulses_us()
            pulses[2] = FAILSAFE_THROTTLE_US
            return sbus_frame(pulses, SBUS_FAILSAFE_FLAG)
        return sbus_frame(row.pulses_us())
