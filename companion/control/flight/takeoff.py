"""Runway take-off: full throttle on the centreline, rotate at speed, climb out straight.

The centreline is the line from where the roll started along the heading the aircraft
had then. On the ground the rudder (and the nose wheel or tail wheel it moves) steers
back onto it; after rotation the wings are held level on the same line until the
aircraft is high enough for normal guidance.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass

from companion.geodesy import wrap_pi

CLIMB_OUT_AGL_M = 15.0  # below this the aircraft flies the runway line with wings level
STEER_LOOKAHEAD_M = 30.0


class Phase(enum.IntEnum):
    """Where in the take-off the aircraft is."""

    GROUND_ROLL = 1
    ROTATE = 2
    CLIMB_OUT = 3  # high enough for normal guidance


@dataclass(frozen=True)
class TakeoffDemand:
    """Attitude, throttle and (on the ground) rudder for this step."""

    phase: Phase
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
        self.phase = Phase.GROUND_ROLL

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
    ) -> TakeoffDemand:
        """What to do now; ``v`` holds the control parameters by name."""
        agl = alt_msl - self.ground_msl
        if self.phase == Phase.GROUND_ROLL and airspeed >= v["TKOFF_ROTATE_SPD"]:
            self.phase = Phase.ROTATE
        if self.phase == Phase.ROTATE and agl >= CLIMB_OUT_AGL_M:
            self.phase = Phase.CLIMB_OUT
        throttle = v["THR_MAX"]
        # The rudder holds the runway heading until the aircraft is high enough for normal
        # guidance: on the wheels it steers, just after rotation (slow, wings level) it
        # keeps a gust or a tailwind from swinging the nose round.
        heading_dem = self.heading - math.atan2(self.xtrack(pos), STEER_LOOKAHEAD_M)
        rudder = v["TKOFF_STEER_P"] * wrap_pi(heading_dem - yaw) - 0.3 * yaw_rate
        rudder = max(-1.0, min(1.0, rudder))
        if self.phase == Phase.GROUND_ROLL:
            pitch = math.radians(v["TKOFF_GND_PITCH"])
            return TakeoffDemand(self.phase, 0.0, pitch, throttle, rudder)
        pitch = math.radians(v["TKOFF_PITCH_DEG"])
        return TakeoffDemand(self.phase, 0.0, pitch, throttle, rudder)
