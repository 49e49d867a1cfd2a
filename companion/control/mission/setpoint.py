"""What the mission executor (and the modes other than Mission) ask the flight controller
to fly: a line, a circle, a take-off or a landing, in the home-centred north/east frame."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

Point = tuple[float, float]


class Kind(enum.IntEnum):
    """What the controller is asked to fly."""

    TAKEOFF = 1  # runway take-off, then climb along the runway heading
    LINE = 2  # track a → b
    CIRCLE = 3  # circle b
    LAND = 4  # approach along a → b down to alt_msl at b, flare, roll out, stop


@dataclass(frozen=True)
class Setpoint:
    """One guidance target in the home-centred north/east frame (metres, MSL altitude)."""

    kind: Kind
    a: Point
    b: Point
    alt_msl: float
    radius: float = 0.0
    clockwise: bool = True
    speed: float = math.nan  # NaN: the cruise speed
    from_alt: float = math.nan  # LAND: the height at a, where the glide path starts
    approach: bool = False  # the leg or circle a landing's final starts from (leads_to_landing)
