"""Runway take-off: full throttle on the centreline, rotate at speed, climb out straight.

The centreline is the line from where the roll started along the heading the aircraft
had then. On the ground the rudder (and the nose wheel or tail wheel it moves) steers
back onto it; after rotation the wings are held level on the same line until the
aircraft is high enough for normal guidance.

A roll that does not reach ``ROLLING_M_S`` of ground speed within ``TKOFF_TIMEOUT``
seconds (brakes dragging, a wheel in soft ground, a throttle that does nothing) is
aborted: idle, brakes, disarm, as ArduPlane's parameter of that name does. 0: no limit.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from companion.control.flight.output import ControlOutput
from companion.geodesy import wrap_pi
from companion.messages.control import TakeoffPhase
from mavlink_dialect import companion as d

CLIMB_OUT_AGL_M = 15.0  # below this the aircraft flies the runway line with wings level
STEER_LOOKAHEAD_M = 30.0
ROLLING_M_S = 4.0  # the ground speed a take-off roll must reach within TKOFF_TIMEOUT


@dataclass(frozen=True)
class TakeoffDemand:
    """Attitude, throttle and (on the ground) rudder for this step."""

    phase: TakeoffPhase
    roll: float
    pitch: float
    throttle: float
    rudder: float


class RunwayTakeoff:
    """The take-off of one flight, from the position and heading at its start."""

    def __init__(self, start: tuple[float, float], heading: float, ground_msl: float) -> None:
        self.start = start
        self.heading = heading
        self.ground_msl = ground_msl
        self.phase = TakeoffPhase.GROUND_ROLL
        self.rolling_s = 0.0  # seconds of ground roll before ROLLING_M_S was reached
        self.rolled = False  # ROLLING_M_S reached (or the take-off began in the air)
        self.abort_said = False

    def centreline_point(self, distance: float) -> tuple[float, float]:
        """The point ``distance`` metres down the runway from the start."""
        return (
            self.start[0] + distance * math.cos(self.heading),
            self.start[1] + distance * math.sin(self.heading),
        )

    def xtrack(self, pos: tuple[float, float]) -> float:
        """Metres right of the centreline."""
        dn, de = pos[0] - self.start[0], pos[1] - self.start[1]
        return -dn * math.sin(self.heading) + de * math.cos(self.heading)

    def step(
        self,
        pos: tuple[float, float],
        alt_msl: float,
        yaw: float,
        yaw_rate: float,
        airspeed: float,
        v: Mapping[str, float],
        ground_speed: float,
        dt: float,
    ) -> TakeoffDemand:
        """What to do now (``dt`` seconds after the last step, at ``ground_speed``); ``v``
        holds the control parameters by name."""
        if self._too_slow(ground_speed, dt, v["TKOFF_TIMEOUT"]):
            self.phase = TakeoffPhase.ABORTED
        if self.phase == TakeoffPhase.ABORTED:
            return TakeoffDemand(self.phase, 0.0, 0.0, 0.0, 0.0)
        agl = alt_msl - self.ground_msl
        if self.phase == TakeoffPhase.GROUND_ROLL and airspeed >= v["TKOFF_ROTATE_SPD"]:
            self.phase = TakeoffPhase.ROTATE
        if self.phase == TakeoffPhase.ROTATE and agl >= CLIMB_OUT_AGL_M:
            self.phase = TakeoffPhase.CLIMB_OUT
        throttle = v["THR_MAX"]
        # The rudder holds the runway heading until the aircraft is high enough for normal
        # guidance: on the wheels it steers, just after rotation (slow, wings level) it
        # keeps a gust or a tailwind from swinging the nose round.
        heading_dem = self.heading - math.atan2(self.xtrack(pos), STEER_LOOKAHEAD_M)
        rudder = v["TKOFF_STEER_P"] * wrap_pi(heading_dem - yaw) - 0.3 * yaw_rate
        rudder = max(-1.0, min(1.0, rudder))
        if self.phase == TakeoffPhase.GROUND_ROLL:
            pitch = math.radians(v["TKOFF_GND_PITCH"])
            return TakeoffDemand(self.phase, 0.0, pitch, throttle, rudder)
        pitch = math.radians(v["TKOFF_PITCH_DEG"])
        return TakeoffDemand(self.phase, 0.0, pitch, throttle, rudder)

    def _too_slow(self, ground_speed: float, dt: float, timeout_s: float) -> bool:
        """Whether the roll has gone on ``timeout_s`` without reaching ``ROLLING_M_S``."""
        if self.rolled or self.phase != TakeoffPhase.GROUND_ROLL:
            return False
        self.rolled = ground_speed >= ROLLING_M_S
        self.rolling_s += dt
        return not self.rolled and timeout_s > 0.0 and self.rolling_s > timeout_s

    def abort(
        self, out: ControlOutput, speed: float, v: Mapping[str, float], said: list[tuple[int, str]]
    ) -> ControlOutput:
        """The aborted roll's output: idle, brakes, disarm; the operator told once."""
        if not self.abort_said:
            text = f"Takeoff aborted: {speed:.1f} m/s after {v['TKOFF_TIMEOUT']:.0f} s"
            said.append((d.MAV_SEVERITY_CRITICAL, text))
            self.abort_said = True
        out.throttle, out.brakes, out.disarm = 0.0, max(v["LAND_BRAKE"], 0.5), True
        return out
