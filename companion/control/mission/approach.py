"""The item a landing's final starts from: flown so the final starts where the plan put it.

Pure geometry on the home-centred north/east frame (metres); the executor decides when.
"""

from __future__ import annotations

import math
from dataclasses import replace

from companion.control.flight.flare_aim import FLARE_SHARE_MAX
from companion.control.laws.fillet import LOOP_TURN_RAD
from companion.control.mission.items import MissionItem
from companion.control.mission.leg_geometry import corner_turn, distance
from companion.geodesy import LocalFrame
from mavlink_dialect import companion as d

Point = tuple[float, float]
NOTE_WIDER = 1.1  # a landing circle flown this much wider than planned is said
NOTE_LOWER_M = 2.0  # and one left this much lower
# A final shorter than this many turn radii after a loop's corner is begun from a circle:
# the loop takes up to two radii of it, and the glide needs the rest lined up. Turning back
# 180° on a final of 3.7 radii, a C172 came out of the loop 250 m beside the final and met
# its line only in the flare, 12.8 m beside the point.
LINE_UP_RADII = 4.0
# And so is any final the aircraft comes to back along its own line (a go-around's second
# approach, climbed out past the runway): the 180° loop at its start leaves it two radii
# beside the final. After a go-around in a 5 m/s crosswind a Cub turned so onto a 700 m
# final (6 radii), drifted 150 m beside it, lined up only at 12 m and 29 m/s, and touched
# down 19 m aside.
REVERSAL_RAD = math.radians(150.0)
LINE_UP_TEXT = "Land: circling at item %d to line up with the final"  # said as it begins


def circle_down(
    item: MissionItem, wp: Point, land: Point, pos: Point, radius: float, frame: LocalFrame
) -> MissionItem:
    """A LOITER_TO_ALT standing in for the waypoint ``item`` at ``wp`` reached too high:
    its circle passes through the waypoint tangent to the final towards ``land``, on the
    side the aircraft is on, so it is left at the waypoint on the final's course."""
    length = max(distance(wp, land), 1.0)
    right = (-(land[1] - wp[1]) / length, (land[0] - wp[0]) / length)
    side = 1.0 if _beside(pos, wp, land) >= 0.0 else -1.0
    lat, lon = frame.latlon(wp[0] + side * radius * right[0], wp[1] + side * radius * right[1])
    return replace(item, command=d.MAV_CMD_NAV_LOITER_TO_ALT, param1=1.0,
                   param2=side * radius, x=round(lat * 1e7), y=round(lon * 1e7))  # fmt: skip


def turns_back_onto(a: Point, b: Point, land: Point | None, turn_radius: float) -> bool:
    """Whether the final from ``b`` to ``land`` turns back on the leg ``a`` → ``b`` more than
    a corner's arc turns (``LOOP_TURN_RAD``) and is too short (``LINE_UP_RADII`` turn
    radii) for the loop that turns onto it to leave the aircraft lined up on it before the
    flare: the aircraft would glide in the loop and meet the final across it; or turns
    back more than ``REVERSAL_RAD`` from within a turn radius of the final's line,
    whatever its length (False with no final: ``land`` None)."""
    if land is None or distance(a, b) < 1.0:
        return False
    turn = abs(corner_turn(a, b, land))
    if turn <= LOOP_TURN_RAD:
        return False
    if distance(b, land) < LINE_UP_RADII * turn_radius:
        return True
    return turn > REVERSAL_RAD and abs(_beside(a, b, land)) < turn_radius


def _beside(pos: Point, b: Point, land: Point) -> float:
    """How far ``pos`` is beside the line through ``b`` and ``land`` (m, + right)."""
    length = max(distance(b, land), 1.0)
    return ((pos[1] - b[1]) * (land[0] - b[0]) - (pos[0] - b[0]) * (land[1] - b[1])) / length


def final_height(
    alt: float, start: Point, land: Point, land_alt: float, steepest: float, flare: Point
) -> float:
    """The height to leave a landing circle at, at ``start``, for a final no steeper than
    ``steepest`` (rad; 0: the plan's ``alt``): a Cub idling down a 6° final gained 6 m/s
    and floated 34 m long. The glide ends where the flare begins, ``flare`` (its run before
    the touchdown point, at most ``FLARE_SHARE_MAX`` of the final, and its height):
    counted to the touchdown point instead, a C172's 227 m final from 20 m was glided at
    8°, dived at its least pitch to 34 m/s, flared from 13 m and touched down 42 m long."""
    if steepest <= 0.0:
        return alt
    length = distance(start, land)
    run, flare_alt = flare
    glide = length - min(run, FLARE_SHARE_MAX * length)
    return min(alt, land_alt + flare_alt + glide * math.tan(steepest))


def circle_note(planned: tuple[float, float], flown: tuple[float, float]) -> str | None:
    """What to tell the operator of a landing circle flown wider (the aircraft's turn) or
    left lower (``LAND_SLOPE_MAX``) than the plan says; (radius, height above home) each.
    None when it is flown as planned, or near enough that the map would not show it (a
    250 m circle flown 253 m wide). A ground station shows the plan's circle and height,
    and its operator would otherwise read the difference as a fault."""
    (radius, height), (flown_radius, flown_height) = planned, flown
    if flown_radius <= radius * NOTE_WIDER and height - flown_height <= NOTE_LOWER_M:
        return None
    return (f"Land circle: {flown_radius:.0f} m at {flown_height:.0f} m"
            f" (plan: {radius:.0f} m at {height:.0f} m)")  # fmt: skip
