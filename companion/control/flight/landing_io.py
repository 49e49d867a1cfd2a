"""What the landing law (landing.py) takes in and gives out: the aircraft's state as the
navigator sees it, and the demand to fly now."""

from __future__ import annotations

import math
from dataclasses import dataclass

from companion.messages.control import LandPhase

Point = tuple[float, float]


@dataclass(frozen=True)
class LandingDemand:
    """What to fly now.

    APPROACH and GO_AROUND: track ``line`` at ``alt_msl`` and ``speed`` with normal
    energy control (``pitch`` and ``throttle`` are NaN). FLARE and ROLLOUT: ``pitch``,
    ``throttle`` and the bank limit are given; ``rudder`` (NaN: the yaw damper) steers
    on the ground.
    """

    phase: LandPhase
    line: tuple[Point, Point]
    alt_msl: float
    speed: float
    pitch: float = math.nan
    throttle: float = math.nan
    rudder: float = math.nan
    elevator: float = math.nan  # ROLLOUT: held directly when given
    brakes: float = 0.0  # 0 off .. 1 full
    roll_limit: float = math.nan
    disarm: bool = False
    flaps: float = 0.0
    climb_ff: float = 0.0  # m/s: how fast the glide path descends under the aircraft


@dataclass(frozen=True)
class AircraftState:
    """The navigator's view: local north/east position and velocity, MSL height."""

    pos: Point
    vel: Point
    alt_msl: float
    climb_rate: float  # m/s, + up
    pitch: float
    yaw: float
    yaw_rate: float
    range_height: float = math.nan  # m above the ground by the rangefinder; NaN: none usable
    airspeed: float = math.nan  # m/s; NaN: unknown
