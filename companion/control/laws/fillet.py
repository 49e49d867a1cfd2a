"""The arc that joins one straight leg to the next: where a turn starts, ends and circles.

A waypoint corner is flown as a circular arc of the turn radius tangent to both legs, as
an aircraft must fly it anyway: it starts turning ``R·tan(θ/2)`` before the corner (θ
the change of course) and ends on the new leg as far past it, with the wings levelling
as it gets there. Guided only by the new line, L1 begins the turn when the aircraft is
one L1 distance from that line, which for a turn radius longer than L1 overshoots the
new leg by tens of metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

MIN_TURN_RAD = math.radians(3.0)  # below this a corner is flown as a straight line
MAX_TURN_RAD = math.radians(175.0)  # beyond this (a reversal) L1 turns from the switch point
# A corner sharper than 120° flown at the planned radius would begin and end its arc far
# from the corner (2.4 radii for 135°, 3.3 for 146°): it is flown tighter instead, its arc
# starting no earlier than a 120° one's (1.7 radii), down to this fraction of the planned
# radius. Planned at 70 % of the bank limit at the fastest ground speed, 0.7 of the radius
# asks for tan(bank) 1/0.7 times larger: 41° of a 45° limit, downwind only. With the lead of
# a 135° corner the c172p in a 5 m/s wind (radius 280 m) was still on the arc, 28-58 m off
# the new line, 500 m past the corner, where the straight part is scored; with a 120° lead
# it is on the line by then (closed loop, jump plan: p95 14.5 -> 0.9 m).
SHARP_LEAD_TAN = math.tan(math.radians(120.0) / 2.0)
SHARP_RADIUS_SCALE = 0.7


@dataclass(frozen=True)
class Fillet:
    """Geometry of one corner (north/east metres)."""

    corner: tuple[float, float]
    u_in: tuple[float, float]  # unit vector along the leg flown into the corner
    u_out: tuple[float, float]  # and along the leg flown out of it
    lead: float  # distance from the corner to either tangent point
    centre: tuple[float, float]
    radius: float
    clockwise: bool  # a right turn


def corner_arc(turn_rad: float, radius: float, l_in: float, l_out: float) -> tuple[float, float]:
    """Lead (distance from the corner to either tangent point) and radius of the arc that
    turns through ``turn_rad`` between legs ``l_in`` and ``l_out`` long, planned at ``radius``.

    The mission executor switches legs at this lead and guidance flies this arc: one
    geometry for both, or the aircraft reaches the arc's start already past it.
    """
    half_tan = math.tan(abs(turn_rad) / 2.0)
    if half_tan <= 0.0 or radius <= 0.0:
        return 0.0, radius
    if abs(turn_rad) > MAX_TURN_RAD:  # no arc: switch legs as early as for a 120° corner
        return min(radius * SHARP_LEAD_TAN, 0.5 * l_in, 0.5 * l_out), radius
    radius *= max(SHARP_RADIUS_SCALE, min(1.0, SHARP_LEAD_TAN / half_tan))
    # Short legs leave no room for the whole arc: a tighter one, flown at the bank limit.
    lead = min(radius * half_tan, 0.5 * l_in, 0.5 * l_out)
    return lead, lead / half_tan


def fillet(
    prev: tuple[float, float], corner: tuple[float, float], nxt: tuple[float, float], radius: float
) -> Fillet | None:
    """The arc of ``radius`` from leg prev→corner onto leg corner→nxt (None: no turn)."""
    d_in = (corner[0] - prev[0], corner[1] - prev[1])
    d_out = (nxt[0] - corner[0], nxt[1] - corner[1])
    l_in, l_out = math.hypot(*d_in), math.hypot(*d_out)
    if l_in < 1.0 or l_out < 1.0 or radius <= 0.0:
        return None
    u_in = (d_in[0] / l_in, d_in[1] / l_in)
    u_out = (d_out[0] / l_out, d_out[1] / l_out)
    turn = math.atan2(
        u_in[0] * u_out[1] - u_in[1] * u_out[0], u_in[0] * u_out[0] + u_in[1] * u_out[1]
    )
    if abs(turn) < MIN_TURN_RAD or abs(turn) > MAX_TURN_RAD:
        return None
    lead, radius = corner_arc(turn, radius, l_in, l_out)
    sign = 1.0 if turn > 0 else -1.0
    right = (-u_out[1] * sign, u_out[0] * sign)  # towards the centre
    t_out = (corner[0] + u_out[0] * lead, corner[1] + u_out[1] * lead)
    centre = (t_out[0] + right[0] * radius, t_out[1] + right[1] * radius)
    return Fillet(corner, u_in, u_out, lead, centre, radius, turn > 0)


def arc_phase(f: Fillet, pos: tuple[float, float], exit_early: float = 0.0) -> int:
    """0 before the arc's start, 1 on it, 2 within ``exit_early`` m of its end or past it."""
    rel = (pos[0] - f.corner[0], pos[1] - f.corner[1])
    along_in = rel[0] * f.u_in[0] + rel[1] * f.u_in[1]
    along_out = rel[0] * f.u_out[0] + rel[1] * f.u_out[1]
    if along_out >= f.lead - exit_early:
        return 2
    return 1 if along_in > -f.lead else 0
