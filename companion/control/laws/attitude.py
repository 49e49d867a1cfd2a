"""Roll and pitch loops with airspeed scaling and bounded integrators, and a yaw damper.

Each surface command is ``scaler·(kp·angle error − kd·body rate) + integrator``; the
scaler (cruise speed / airspeed, bounded) keeps the loop gain constant as the dynamic
pressure changes, as ArduPlane's speed scaler does. In a turn the pitch loop adds the
pitch rate a coordinated turn needs, and the rudder drives the yaw rate towards
``g·sin(φ)/V`` so the turn stays coordinated.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from companion.control.laws.limits import clamp
from companion.geodesy import STANDARD_GRAVITY as G
from companion.geodesy import wrap_pi


@dataclass
class AttitudeGains:
    """Gains of the three loops (surface fraction per radian or per rad/s)."""

    roll_p: float = 1.0
    roll_d: float = 0.1
    roll_i: float = 0.2
    roll_imax: float = 0.2
    pitch_p: float = 1.5
    pitch_d: float = 0.2
    pitch_i: float = 0.3
    pitch_imax: float = 0.3
    yaw_damp: float = 3.5
    scaling_speed: float = 30.0  # m/s at which the gains are as given


@dataclass(frozen=True)
class Surfaces:
    """Normalised commands: aileron/elevator/rudder in [-1, 1] (stick convention)."""

    aileron: float
    elevator: float
    rudder: float


class AttitudeController:
    """Holds the integrators between steps."""

    def __init__(self, gains: AttitudeGains) -> None:
        self.gains = gains
        self.roll_integ = 0.0
        self.pitch_integ = 0.0

    def reset(self) -> None:
        """Forget the integrators (on the ground, on a mode change that needs it)."""
        self.roll_integ = self.pitch_integ = 0.0

    def scaler(self, airspeed: float) -> float:
        """How much to scale the gains at this airspeed (bounded to [0.5, 2])."""
        return clamp(self.gains.scaling_speed / max(airspeed, 1.0), 0.5, 2.0)

    def step(
        self,
        roll_dem: float,
        pitch_dem: float,
        att: tuple[float, float],
        rates: tuple[float, float, float],
        airspeed: float,
        dt: float,
        integrate: bool = True,
    ) -> Surfaces:
        """Surface commands for the demanded roll and pitch (rad), given attitude and rates."""
        g = self.gains
        roll, pitch = att
        p, q, r = rates
        k = self.scaler(airspeed)
        v = max(airspeed, 5.0)
        roll_err = wrap_pi(roll_dem - roll)  # the short way round (Acro rolls through ±π)
        # A coordinated turn pitches the body at g·tan φ·sin φ / V.
        q_turn = G / v * math.tan(clamp(roll, -1.2, 1.2)) * math.sin(roll)
        pitch_err = pitch_dem - pitch
        if integrate:
            self.roll_integ = clamp(
                self.roll_integ + g.roll_i * k * roll_err * dt, -g.roll_imax, g.roll_imax
            )
            self.pitch_integ = clamp(
                self.pitch_integ + g.pitch_i * k * pitch_err * dt, -g.pitch_imax, g.pitch_imax
            )
        aileron = k * (g.roll_p * roll_err - g.roll_d * p) + self.roll_integ
        elevator = k * (g.pitch_p * pitch_err + g.pitch_d * (q_turn - q)) + self.pitch_integ
        r_turn = G / v * math.sin(roll) * math.cos(pitch)
        rudder = k * g.yaw_damp * (r_turn - r)
        return Surfaces(clamp(aileron, -1, 1), clamp(elevator, -1, 1), clamp(rudder, -1, 1))
