"""From a receiver's pulse widths to stick positions and a mode-switch position.

ArduPilot's conventions and parameter names, so a pilot's calibration carries over:
``RCn_MIN``/``RCn_MAX``/``RCn_TRIM`` (µs) and ``RCn_REVERSED`` per channel, ``RCMAP_ROLL``,
``RCMAP_PITCH``, ``RCMAP_THROTTLE``, ``RCMAP_YAW`` (1-based channel numbers, AETR by
default), ``FLTMODE_CH`` (the switch channel, 0: none) read in six bands of pulse width
(≤1230, ≤1360, ≤1490, ≤1620, ≤1749, above) as positions 0..5 (FLTMODE1..6), and
``THR_FS_VALUE``: a throttle pulse below it is a receiver's failsafe, not a pilot.
Sticks follow ``ActuatorCommand``'s convention: a larger pulse is roll right, nose up
(stick back), yaw right; reverse a channel whose transmitter says otherwise. Pure.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from companion.params import ParamDecl

CALIBRATED_CHANNELS = 8  # RC1..RC8 have a calibration; 9..18 are reported raw
MODE_BANDS_US = (1230, 1360, 1490, 1620, 1749)


def _channel_params(n: int) -> tuple[ParamDecl, ...]:
    return (
        ParamDecl(f"RC{n}_MIN", 1100.0, 800.0, 2200.0, "us", f"channel {n}: lowest pulse"),
        ParamDecl(f"RC{n}_MAX", 1900.0, 800.0, 2200.0, "us", f"channel {n}: highest pulse"),
        ParamDecl(f"RC{n}_TRIM", 1500.0, 800.0, 2200.0, "us", f"channel {n}: centre pulse"),
        ParamDecl(f"RC{n}_REVERSED", 0.0, 0.0, 1.0, "", f"channel {n}: 1 reverses it"),
    )


RC_PARAMS: tuple[ParamDecl, ...] = (
    *(p for n in range(1, CALIBRATED_CHANNELS + 1) for p in _channel_params(n)),
    ParamDecl("RCMAP_ROLL", 1.0, 1.0, 8.0, "", "channel of the roll stick"),
    ParamDecl("RCMAP_PITCH", 2.0, 1.0, 8.0, "", "channel of the pitch stick"),
    ParamDecl("RCMAP_THROTTLE", 3.0, 1.0, 8.0, "", "channel of the throttle stick"),
    ParamDecl("RCMAP_YAW", 4.0, 1.0, 8.0, "", "channel of the rudder stick"),
    ParamDecl("FLTMODE_CH", 8.0, 0.0, 18.0, "", "channel of the flight-mode switch; 0: none"),
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


def _calibration(p: Mapping[str, float], ch: int) -> tuple[float, float, float, bool]:
    lo, hi, trim = p[f"RC{ch}_MIN"], p[f"RC{ch}_MAX"], p[f"RC{ch}_TRIM"]
    return lo, hi, min(max(trim, lo), hi), p[f"RC{ch}_REVERSED"] >= 0.5


def _pulse(pulses: Sequence[int], ch: int) -> int:
    return pulses[ch - 1] if 1 <= ch <= len(pulses) else 0


def centred(pulse: float, lo: float, hi: float, trim: float, reversed_: bool) -> float:
    """A centring stick in [-1, 1]: the trim is 0, each side scaled to its own end."""
    if pulse >= trim:
        value = (pulse - trim) / (hi - trim) if hi > trim else 0.0
    else:
        value = (pulse - trim) / (trim - lo) if trim > lo else 0.0
    value = max(-1.0, min(1.0, value))
    return -value if reversed_ else value


def ranged(pulse: float, lo: float, hi: float, reversed_: bool) -> float:
    """A throttle-like channel in [0, 1] from its lowest to its highest pulse."""
    value = (pulse - lo) / (hi - lo) if hi > lo else 0.0
    value = max(0.0, min(1.0, value))
    return 1.0 - value if reversed_ else value


def switch_position(pulse: int) -> int:
    """The six-position band of a mode-switch pulse (0..5), -1 for no pulse."""
    if pulse <= 0:
        return -1
    return sum(pulse > edge for edge in MODE_BANDS_US)


@dataclass(frozen=True)
class StickMap:
    """The RC parameters resolved once into channels and calibrations: a receiver sends
    50 frames a second, its parameters change when the pilot calibrates."""

    axes: tuple[tuple[int, float, float, float, bool], ...]  # roll, pitch, yaw
    throttle: tuple[int, float, float, bool]
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
        lo, hi, _trim, rev = _calibration(p, thr_ch)
        return cls(tuple(axes), (thr_ch, lo, hi, rev), round(p["FLTMODE_CH"]), p["THR_FS_VALUE"])

    def sticks(self, pulses: Sequence[int]) -> Sticks:
        """The pilot's sticks from the channels' pulse widths."""
        roll, pitch, yaw = (
            centred(_pulse(pulses, ch), lo, hi, trim, rev) for ch, lo, hi, trim, rev in self.axes
        )
        thr_ch, lo, hi, rev = self.throttle
        thr_pulse = _pulse(pulses, thr_ch)
        mode_ch = self.mode_ch
        return Sticks(
            roll=roll,
            pitch=pitch,
            yaw=yaw,
            throttle=ranged(thr_pulse, lo, hi, rev),
            mode_switch=switch_position(_pulse(pulses, mode_ch)) if mode_ch else -1,
            throttle_low=thr_pulse < self.throttle_failsafe_us,
        )


def sticks(pulses: Sequence[int], p: Mapping[str, float]) -> Sticks:
    """The pilot's sticks from the channels' pulse widths and the RC parameters."""
    return StickMap.from_params(p).sticks(pulses)
