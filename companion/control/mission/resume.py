"""A mission taken up in the air: the leg it was on, the corner before it, and its speed.

A controller restarted in flight (its process killed, or the whole vehicle) knows only
the item the mission was flying to (the commander keeps it). Starting that item from
where the aircraft is would draw a new leg from here: shorter than the planned one, so
the corner ahead gets a lead cut to half of what is left and an arc tighter than the
aircraft can fly (it overshot the next leg by 121 m), and the corner it may be turning
through is forgotten. Instead the leg is drawn again from the previous item's place,
as the unbroken flight flew it, when the aircraft is on it; the corner before it is
known from the item before that.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from companion.control.mission.executor import Kind, MissionExecutor, Setpoint
from companion.control.mission.items import PASSED_OVER, change_speed
from companion.control.mission.zones import point_to_segment
from mavlink_dialect import companion as d

# On the leg or the corner's arc into it: within this many turn radii of the segment (an
# arc up to a 120° corner stays within 1.7 radii of the leg it turns onto).
ON_LEG_RADII = 2.0
# A leg whose start is not known (after a take-off whose climb ended off its line, after a
# loiter, a jump) is drawn back from here at least this many turn radii: the lead of the
# corner at its end is at most half the leg, and no more than 1.7 radii.
UNKNOWN_START_RADII = 4.0
Point = tuple[float, float]


@dataclass(frozen=True)
class ResumedLeg:
    """Where the leg to the current item starts, and the start of the leg before it."""

    start: Point
    corner_from: Point | None = None  # the corner at ``start`` is flown as an arc from here
    speed: float = math.nan  # the last DO_CHANGE_SPEED before the item (NaN: cruise)

    def line_before(self, setpoint: Setpoint) -> tuple[Point, Point] | None:
        """The leg flown before ``setpoint`` (the resumed executor's first), whose end is
        the corner the controller flies as an arc; None when there is no such corner."""
        if setpoint.kind != Kind.LINE:
            return None
        if setpoint.a == self.start:
            return None if self.corner_from is None else (self.corner_from, self.start)
        return (self.start, setpoint.a)  # the first step reached the item: its corner


def start_mission(
    ex: MissionExecutor, first: int, pos: Point, alt_msl: float, turn_radius: float | None
) -> ResumedLeg | None:
    """Start ``ex`` at item ``first``: from where the aircraft is on the ground
    (``turn_radius`` None), on the leg it was on in the air (its ``ResumedLeg`` returned)."""
    if turn_radius is None:
        ex.start(first, pos, alt_msl)
        return None
    leg = resumed_leg(ex, first, pos, turn_radius)
    ex.start(first, pos, alt_msl, leg.start)
    ex.speed = leg.speed
    return leg


def resumed_leg(ex: MissionExecutor, first: int, pos: Point, turn_radius: float) -> ResumedLeg:
    """The leg of a mission taken up at item ``first`` with the aircraft at ``pos``."""
    items = ex.items
    speed = _speed_before(ex, first)
    if not 0 <= first < len(items) or items[first].command != d.MAV_CMD_NAV_WAYPOINT:
        return ResumedLeg(pos, None, speed)
    b = ex.point_of(items[first], pos)
    prev = _previous_place(ex, first)
    waypoint = prev is not None and items[prev].command == d.MAV_CMD_NAV_WAYPOINT
    # After a waypoint the aircraft may be on the corner's arc into the leg; after a
    # take-off the leg began where the climb ended, on the line from its place only if
    # the aircraft is on that line now.
    tolerance = items[first].acceptance_m(ex.config.wp_radius)
    if waypoint:
        tolerance = max(tolerance, ON_LEG_RADII * turn_radius)
    if prev is not None and point_to_segment(pos, ex.point_of(items[prev], pos), b) <= tolerance:
        before = _previous_place(ex, prev) if waypoint else None
        corner_from = ex.point_of(items[before], pos) if before is not None else None
        return ResumedLeg(ex.point_of(items[prev], pos), corner_from, speed)
    # Not known, or not on it: the line from here, drawn back far enough for the corner.
    dist = math.hypot(b[0] - pos[0], b[1] - pos[1])
    if dist < 1.0:
        return ResumedLeg(pos, None, speed)
    back = max(dist, UNKNOWN_START_RADII * turn_radius) / dist
    start = (b[0] - (b[0] - pos[0]) * back, b[1] - (b[1] - pos[1]) * back)
    return ResumedLeg(start, None, speed)


def _previous_place(ex: MissionExecutor, seq: int) -> int | None:
    """The item before ``seq`` (past DO items) that is a waypoint or a take-off with a
    place of its own; None when it is anything else."""
    for i in range(seq - 1, -1, -1):
        item = ex.items[i]
        if item.command in PASSED_OVER:
            continue
        has_place = item.x != 0 or item.y != 0
        takeoff_or_wp = item.command in (d.MAV_CMD_NAV_WAYPOINT, d.MAV_CMD_NAV_TAKEOFF)
        return i if takeoff_or_wp and has_place else None
    return None


def _speed_before(ex: MissionExecutor, seq: int) -> float:
    speed = math.nan
    for item in ex.items[: max(0, seq)]:
        if item.command == d.MAV_CMD_DO_CHANGE_SPEED:
            speed = change_speed(item, speed)
    return speed
