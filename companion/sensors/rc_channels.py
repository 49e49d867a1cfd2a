"""From a receiver's pulse widths to stick positions and a mode-switch position.

ArduPilot's conventions and parameter names, so a pilot's calibration carries over:
``RCn_MIN``/``RCn_MAX``/``RCn_TRIM``/``RCn_DZ`` (µs) and ``RCn_REVERSED`` for each of the
receiver's 18 channels (SBUS: 16 proportional, 2 digital), a dead zone read as ArduPilot
reads it (around the trim of a stick; above the lowest pulse of the throttle); ``RCMAP_ROLL``,
``RCMAP_PITCH``, ``RCMAP_THROTTLE``, ``RCMAP_YAW`` (1-based channel numbers, any of the 18,
AETR by default), ``FLTMODE_CH`` (the switch channel, 0: none) read in six bands of pulse width
(≤1230, ≤1360, ≤1490, ≤1620, ≤1749, above) as positions 0..5 (FLTMODE1..6), and
``THR_FS_VALUE``: a throttle pulse below it is a receiver's failsafe, not a pilot.
Sticks follow ``ActuatorCommand``'s convention: a larger pulse is roll right, nose up
(stick back), yaw right; reverse a channel whose transmitter says otherwise. Pure.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from companion.messages import RC_MAX_CHANNELS
from companion.params import ParamDecl

CALIBRATED_CHANNELS = RC_MAX_CHANNELS  # RC1..RC18: every channel SBUS carries, any a stick
MODE_BANDS_US = (1230, 1360, 1490, 1620, 1749)


def _channel_params(n: int) -> tuple[ParamDecl, ...]:
    return (
        ParamDecl(f"RC{n}_MIN", 1100.0, 800.0, 2200.0, "us", f"channel {n}: lowest pulse"),
        ParamDecl(f"RC{n}_MAX", 1900.0, 800.0, 2200.0, "us", f"channel {n}: highest pulse"),
        ParamDecl(f"RC{n}_TRIM", 1500.0, 800.0, 2200.0, "us", f"channel {n}: centre pulse"),
        ParamDecl.switch(f"RC{n}_REVERSED", 0.0, f"channel {n}: 1 reverses it",
                         "Normal", "Reversed"),
        ParamDecl(f"RC{n}_DZ", 0.0, 0.0, 200.0, "us", f"channel {n}: dead zone (around the "
                  "trim; the throttle's above its lowest pulse)"),
    )  # fmt: skip


def _channel_number(name: str, default: float, least: float, doc: str) -> ParamDecl:
    return ParamDecl(name, default, least, CALIBRATED_CHANNELS, "", doc, integer=True)


RC_PARAMS: tuple[ParamDecl, ...] = (
    *(p for n in range(1, CALIBRATED_CHANNELS + 1) for p in _channel_params(n)),
    _channel_number("RCMAP_ROLL", 1.0, 1.0, "channel of the roll stick"),
    _channel_number("RCMAP_PITCH", 2.0, 1.0, "channel of the pitch stick"),
    _channel_number("RCMAP_THROTTLE", 3.0, 1.0, "channel of the throttle stick"),
    _channel_number("RCMAP_YAW", 4.0, 1.0, "channel of the rudder stick"),
    _channel_number("FLTMODE_CH", 8.0, 0.0, "mode switch channel; 0: none"),
    ParamDecl("THR_FS_VALUE", 950.0, 800.0, 2200.0, "us", "throttle below this: receiver failsafe"),
)


@dataclass(frozen=True)
class Sticks:
    """Stick positions (roll, pitch, yaw in [-1, 1], throttle in [0, 1]) and the switch."""

    roll: float
    pitch: float
    yaw: float
    throttle: float
    mode_switch: int  # 0..5, -1: no switch
    throttle_low: bool


Calibration = tuple[float, float, float, bool, float]  # min, max, trim, reversed, dead zone


def _calibration(p: Mapping[str, float], ch: int) -> Calibration:
    lo, hi, trim = p[f"RC{ch}_MIN"], p[f"RC{ch}_MAX"], p[f"RC{ch}_TRIM"]
    return lo, hi, min(max(trim, lo), hi), p[f"RC{ch}_REVERSED"] >= 0.5, p[f"RC{ch}_DZ"]


def _pulse(pulses: Sequence[int], ch: int) -> int:
    return pulses[ch - 1] if 1 <= ch <= len(pulses) else 0


def centred(
    pulse: float, lo: float, hi: float, trim: float, reversed_: bool, dz: float = 0.0
) -> float:
    """A centring stick in [-1, 1]: within ``dz`` of the trim is 0, each side scaled from
    the dead zone's edge to its own end."""
    high, low = trim + dz, trim - dz
    if pulse > high:
        value = (pulse - high) / (hi - high) if hi > high else 0.0
    elif pulse < low:
        value = (pulse - low) / (low - lo) if low > lo else 0.0
    else:
        value = 0.0
    value = max(-1.0, min(1.0, value))
    return -value if reversed_ else value


def ranged(pulse: float, lo: float, hi: float, reversed_: bool, dz: float = 0.0) -> float:
    """A throttle-like channel in [0, 1] from ``dz`` above its lowest pulse (its highest,
    reversed) to the other end."""
    if reversed_:
        pulse = lo + hi - pulse
    start = lo + dz
    value = (pulse - start) / (hi - start) if hi > start else 0.0
    return max(0.0, min(1.0, value))


def switch_position(pulse: int) -> int:
    """The six-position band of a mode-switch pulse (0..5), -1 for no pulse."""
    if pulse <= 0:
        return -1
    return sum(pulse > edge for edge in MODE_BANDS_US)


@dataclass(frozen=True)
class StickMap:
    """The RC parameters resolved once into channels and calibrations: a receiver sends
    50 frames a second, its parameters change when the pilot calibrates."""

    axes: tuple[tuple[int, float, float, float, bool, float], ...]  # roll, pitch, yaw
    throttle: tuple[int, float, float, bool, float]
    mode_ch: int
    throttle_failsafe_us: float

    @classmethod
    def from_params(cls, p: Mapping[str, float]) -> StickMap:
        """The map the parameters ``p`` give."""
        axes = []
        for name in ("RCMAP_ROLL", "RCMAP_PITCH", "RCMAP_YAW"):
            ch = round(p[name])
            axes.append((ch, *_calibration(p, ch)))
        thr_ch = round(p["RCMAP_THROTTLE"])
        lo, hi, _trim, rev, dz = _calibration(p, thr_ch)
        throttle = (thr_ch, lo, hi, rev, dz)
        return cls(tuple(axes), throttle, round(p["FLTMODE_CH"]), p["THR_FS_VALUE"])

    def sticks(self, pulses: Sequence[int]) -> Sticks:
        """The pilot's sticks from the channels' pulse widths."""
        roll, pitch, yaw = (
            centred(_pulse(pulses, ch), lo, hi, trim, rev, dz)
            for ch, lo, hi, trim, rev, dz in self.axes
        )
        thr_ch, lo, hi, rev, dz = self.throttle
        thr_pulse = _pulse(pulses, thr_ch)
        mode_ch = self.mode_ch
        return Sticks(
            roll=roll,
            pitch=pitch,
            yaw=yaw,
            throttle=ranged(thr_pulse, lo, hi, rev, dz),
            mode_switch=switch_position(_pulse(pulses, mode_ch)) if mode_ch else -1,
            throttle_low=thr_pulse < self.throttle_failsafe_us,
        )


def sticks(pulses: Sequence[int], p: Mapping[str, float]) -> Sticks:
    """The pilot's sticks from the channels' pulse widths and the RC parameters."""
    return StickMap.from_params(p).sticks(pulses)
