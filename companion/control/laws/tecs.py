"""Total energy control (after Lambregts): throttle sets the energy, pitch shares it out.

The specific total energy rate ``g·ḣ + V·V̇`` is what throttle changes; the balance
between potential and kinetic energy is what pitch changes. Height and speed errors
become demanded rates through time constants; throttle closes the total-rate error and
pitch the balance-rate error, each with feed-forward, damping and a bounded integrator.
``speed_weight`` (0..2) says whether pitch looks after height (0), speed (2) or both (1).

Underspeed protection (Lambregts' TECS has it, and ArduPilot's and PX4's): below 90 % of
the least airspeed the caller gives, with the throttle already at its most, pitch looks
after speed alone until the least airspeed is back, giving up height before the wing stalls
(a C172 slowed to its least airspeed in a gusty turn, the throttle open and the nose held
up for the height, lost 100 m).
"""

from __future__ import annotations

from dataclasses import dataclass

from companion.control.laws.limits import clamp
from companion.geodesy import STANDARD_GRAVITY as G


@dataclass
class TecsGains:
    """Limits and gains; the throttle figures are fractions of full throttle."""

    time_const: float = 5.0  # s, height error → climb rate demand
    speed_time_const: float = 3.0  # s, speed error → acceleration demand
    climb_max: float = 3.0  # m/s at full throttle and cruise speed
    sink_max: float = 3.0  # m/s at idle
    throttle_trim: float = 0.6  # level flight at cruise speed
    throttle_min: float = 0.0
    throttle_max: float = 1.0
    throttle_damp: float = 0.3
    integ_gain: float = 0.1
    pitch_damp: float = 0.3
    pitch_max: float = 0.35  # rad
    pitch_min: float = -0.25
    speed_weight: float = 1.0
    accel_max: float = 1.5  # m/s²


@dataclass(frozen=True)
class EnergyDemand:
    """Pitch (rad) and throttle (0..1) for the attitude loop and the engine."""

    pitch: float
    throttle: float


class Tecs:
    """Keeps the integrators and the filtered speed derivative between steps."""

    def __init__(self, gains: TecsGains) -> None:
        self.gains = gains
        self.throttle_integ = 0.0
        self.pitch_integ = 0.0
        self._speed: float | None = None
        self.speed_rate = 0.0
        self.underspeed = False
        self._throttle_out = 0.0

    def reset(self, pitch: float = 0.0) -> None:
        """Start again (after takeoff or a mode that flew pitch directly)."""
        self.throttle_integ = 0.0
        self.pitch_integ = pitch
        self._speed = None
        self.speed_rate = 0.0
        self.underspeed = False

    def _track_speed(self, speed: float, dt: float) -> None:
        if self._speed is not None and dt > 0:
            raw = (speed - self._speed) / dt
            self.speed_rate += (raw - self.speed_rate) * min(1.0, dt / 0.5)
        self._speed = speed

    def step(
        self,
        height: float,
        climb_rate: float,
        speed: float,
        height_dem: float,
        speed_dem: float,
        dt: float,
        climb_ff: float = 0.0,
        least_speed: float = 0.0,
    ) -> EnergyDemand:
        """Pitch and throttle for the demanded height (m) and airspeed (m/s).

        ``climb_ff`` (m/s) is how fast the demanded height itself moves (a glide path):
        without it the height would trail a moving demand by a constant error.
        ``least_speed`` (m/s): the airspeed the underspeed protection keeps (0: none).
        """
        g = self.gains
        self._track_speed(speed, dt)
        v = max(speed, 5.0)
        climb_dem = (height_dem - height) / g.time_const + climb_ff
        climb_dem = clamp(climb_dem, -g.sink_max, g.climb_max)
        accel_dem = clamp((speed_dem - speed) / g.speed_time_const, -g.accel_max, g.accel_max)
        # Specific (per unit weight) energy rates, m/s.
        ste_rate_dem = climb_dem + v * accel_dem / G
        ste_rate = climb_rate + v * self.speed_rate / G
        w = 2.0 if self._check_underspeed(speed, least_speed) else clamp(g.speed_weight, 0.0, 2.0)
        seb_rate_dem = climb_dem * (2.0 - w) - v * accel_dem / G * w
        seb_rate = climb_rate * (2.0 - w) - v * self.speed_rate / G * w
        throttle = self._throttle(ste_rate_dem, ste_rate, dt)
        pitch = self._pitch(seb_rate_dem, seb_rate, v, dt)
        self._throttle_out = throttle = g.throttle_max if self.underspeed else throttle
        return EnergyDemand(pitch, throttle)

    def _check_underspeed(self, speed: float, least_speed: float) -> bool:
        """Whether the aircraft is under 90 % of ``least_speed`` with the throttle at its
        most (or has been, and is not back to ``least_speed`` yet)."""
        slow = speed < (least_speed if self.underspeed else 0.9 * least_speed)
        full = self.underspeed or self._throttle_out >= 0.95 * self.gains.throttle_max
        self.underspeed = least_speed > 0.0 and slow and full
        return self.underspeed

    def _throttle(self, ste_rate_dem: float, ste_rate: float, dt: float) -> float:
        g = self.gains
        span = g.climb_max + g.sink_max
        if ste_rate_dem >= 0:
            ff = g.throttle_trim + (g.throttle_max - g.throttle_trim) * ste_rate_dem / g.climb_max
        else:
            ff = g.throttle_trim + (g.throttle_trim - g.throttle_min) * ste_rate_dem / g.sink_max
        error = (ste_rate_dem - ste_rate) / span
        self.throttle_integ = clamp(self.throttle_integ + g.integ_gain * error * dt, -0.3, 0.3)
        raw = ff + g.throttle_damp * error * 4.0 + self.throttle_integ
        return clamp(raw, g.throttle_min, g.throttle_max)

    def _pitch(self, seb_rate_dem: float, seb_rate: float, v: float, dt: float) -> float:
        g = self.gains
        # A balance rate of v·θ per radian of flight-path angle: divide to get radians.
        error = (seb_rate_dem - seb_rate) / v
        self.pitch_integ = clamp(
            self.pitch_integ + g.integ_gain * error * dt * 3.0, g.pitch_min, g.pitch_max
        )
        raw = seb_rate_dem / v + g.pitch_damp * error + self.pitch_integ
        return clamp(raw, g.pitch_min, g.pitch_max)
