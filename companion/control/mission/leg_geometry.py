"""Plane geometry of legs and circles in the home-centred north/east frame (metres)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from companion.geodesy import wrap_pi

Point = tuple[float, float]


def tangent_angle(centre: Point, radius: float, clockwise: bool, target: Point) -> float | None:
    """The angle (from north, about ``centre``) of the point where a circle flown that way
    is left straight towards ``target``; None when the target is inside the circle."""
    dist = distance(centre, target)
    if dist <= radius:
        return None
    bearing = math.atan2(target[1] - centre[1], target[0] - centre[0])
    beta = math.acos(radius / dist)
    return wrap_pi(bearing - beta if clockwise else bearing + beta)


def distance(a: Point, b: Point) -> float:
    """Straight-line distance from ``a`` to ``b``."""
    return math.hypot(b[0] - a[0], b[1] - a[1])


def corner_turn(a: Point, b: Point, c: Point) -> float:
    """The turn (rad, -π..π, positive to the right) at ``b`` from the leg a→b onto b→c."""
    leg_in = math.atan2(b[1] - a[1], b[0] - a[0])
    leg_out = math.atan2(c[1] - b[1], c[0] - b[0])
    return wrap_pi(leg_out - leg_in)


def past_point(a: Point, b: Point, pos: Point) -> bool:
    """True once ``pos`` is beyond the line through ``b`` square to the leg a→b."""
    leg = (b[0] - a[0], b[1] - a[1])
    if math.hypot(*leg) < 1.0:
        return False
    return (pos[0] - b[0]) * leg[0] + (pos[1] - b[1]) * leg[1] > 0.0


@dataclass
class CircleProgress:
    """How far an aircraft has flown round a circle, and since when."""

    swept: float = 0.0  # rad
    last_angle: float | None = None
    started_s: float | None = None

    def track(self, pos: Point, centre: Point, way: float = 0.0) -> float:
        """Add the arc flown since the last position (``way`` +1 clockwise, -1 the other
        way, counting back as negative; 0 either way) and return the angle of ``pos``."""
        angle = math.atan2(pos[1] - centre[1], pos[0] - centre[0])
        if self.last_angle is not None:
            step = wrap_pi(angle - self.last_angle)
            self.swept += step * way if way else abs(step)
        self.last_angle = angle
        return angle

    def off(self) -> float:
        """Off the circle: the next arc starts where it comes back on. Returns NaN."""
        self.last_angle = None
        return math.nan
