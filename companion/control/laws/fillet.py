"""The arc that joins one straight leg to the next: where a turn starts, ends and circles.

A waypoint corner is flown as a circular arc of the turn radius tangent to both legs, as
an aircraft must fly it anyway: it starts turning ``R·tan(θ/2)`` before the corner (θ
the change of course) and ends on the new leg as far past it, with the wings levelling
as it gets there. Guided only by the new line, L1 begins the turn when the aircraft is
one L1 distance from that line, which for a turn radius longer than L1 overshoots the
new leg by tens of metres.

A corner sharper than 120° is flown as a loop instead: such an arc, tangent to both legs,
ends far down the new leg (3.3 radii past a 146° corner), where the leg is meant to be
flown straight. The loop starts where a 120° arc would, turns away from the new leg, then
round onto it, and ends on its line at the corner (as a survey's turnaround does): a third
of a minute longer, and the new leg is flown on its line from the corner on.
"""

from __future__ import annotations

import functools
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
# Sharper than this, a corner is a loop (module doc), flown at the sharp corners' radius and
# begun where a 120° arc begins. The jump plan's 146° corner flown as an arc left the c172p
# on it until 620 m down the new leg in a 5 m/s wind (p95 22.8 m on that leg's straight part).
LOOP_TURN_RAD = math.radians(120.0)
# Its exit may lie before the corner (the loop then joins the new line's extension), no
# more than this many radii: further back it would no longer be the leg's start.
LOOP_MAX_EARLY_EXIT = 1.0
LOOP_SLACK_RAD = 0.5  # how far short of its start an arc still counts as not yet begun


@dataclass(frozen=True)
class Arc:
    """One circular piece of a turn, entered at bearing ``start`` from its centre."""

    centre: tuple[float, float]
    radius: float
    clockwise: bool
    start: float  # rad, bearing from the centre of the point where it begins
    sweep: float  # rad turned on it

    def progress(self, pos: tuple[float, float]) -> float:
        """Angle turned since its start, rad (slightly negative just before it)."""
        bearing = math.atan2(pos[1] - self.centre[1], pos[0] - self.centre[0])
        turned = bearing - self.start if self.clockwise else self.start - bearing
        return (turned + LOOP_SLACK_RAD) % math.tau - LOOP_SLACK_RAD


@dataclass(frozen=True)
class Loop:
    """A corner flown as a loop: ``arcs`` away from the new leg, then round onto it."""

    corner: tuple[float, float]
    u_in: tuple[float, float]
    u_out: tuple[float, float]
    lead: float  # distance before the corner where the first arc begins
    exit: float  # m along the new leg from the corner where the second arc ends (- before)
    radius: float
    arcs: tuple[Arc, Arc]


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
    if abs(turn_rad) > LOOP_TURN_RAD:
        lead = min(radius * SHARP_LEAD_TAN, 0.5 * l_in)
        if _loop_fits(abs(turn_rad), radius * SHARP_RADIUS_SCALE, lead):
            return lead, radius * SHARP_RADIUS_SCALE
    radius *= max(SHARP_RADIUS_SCALE, min(1.0, SHARP_LEAD_TAN / half_tan))
    # Short legs leave no room for the whole arc: a tighter one, flown at the bank limit.
    lead = min(radius * half_tan, 0.5 * l_in, 0.5 * l_out)
    return lead, lead / half_tan


def fillet(
    prev: tuple[float, float], corner: tuple[float, float], nxt: tuple[float, float], radius: float
) -> Fillet | Loop | None:
    """The arc of ``radius`` from leg prev→corner onto leg corner→nxt, or the loop of a
    sharper corner (None: no turn)."""
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
    if abs(turn) > LOOP_TURN_RAD and (exit_beta := _loop_exit(abs(turn), radius, lead)):
        return _loop(corner, u_in, u_out, turn, lead, radius, *exit_beta)
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


def _lead_in_radii(theta: float, exit_r: float) -> tuple[float, float]:
    """The lead (in radii) of a loop round a ``theta`` corner that ends ``exit_r`` radii
    along the new leg, and how far its first arc turns away (rad).

    With x along the leg in, y towards the turn, the first arc's centre is (-lead, -R), the
    second's 2R away at angle β, and the end is e along the new leg:
    ``cos β = (1 + cos θ + e/R·sin θ) / 2`` and ``lead = 2R·sin β + R·sin θ - e·cos θ``.
    """
    sin_t, cos_t = math.sin(theta), math.cos(theta)
    beta = math.acos(max(-1.0, min(1.0, (1.0 + cos_t + exit_r * sin_t) / 2.0)))
    return 2.0 * math.sin(beta) + sin_t - exit_r * cos_t, beta


@functools.lru_cache(maxsize=64)
def _loop_span(theta: float) -> tuple[float, float]:
    """The exits (radii along the new leg) between which a loop's lead grows with its exit:
    from the earliest allowed to the one of the longest lead (beyond it β shrinks to
    nothing, the loop to an arc). One corner's angle is the same at every control step, and
    the executor asks for its lead at each: the search is done once."""
    lo, hi = -LOOP_MAX_EARLY_EXIT, (1.0 - math.cos(theta)) / math.sin(theta)
    peak = max(
        (lo + (hi - lo) * k / 32 for k in range(33)), key=lambda e: _lead_in_radii(theta, e)[0]
    )
    return lo, peak


def _loop_fits(theta: float, radius: float, lead: float) -> bool:
    """Whether a loop begun ``lead`` before a ``theta`` corner can end near it."""
    if radius <= 0.0 or not LOOP_TURN_RAD < theta < math.pi:
        return False
    lo, peak = _loop_span(theta)
    return _lead_in_radii(theta, lo)[0] <= lead / radius <= _lead_in_radii(theta, peak)[0]


def _loop_exit(theta: float, radius: float, lead: float) -> tuple[float, float] | None:
    """Where a loop begun ``lead`` before a ``theta`` corner ends on the new leg (m from the
    corner), and how far its first arc turns away (rad); None if it cannot end near it.
    The lead grows with the exit over ``_loop_span``: the exit is found by bisection there."""
    if not _loop_fits(theta, radius, lead):
        return None
    lo, hi = _loop_span(theta)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _lead_in_radii(theta, mid)[0] < lead / radius else (lo, mid)
    return lo * radius, _lead_in_radii(theta, lo)[1]


def _loop(
    corner: tuple[float, float],
    u_in: tuple[float, float],
    u_out: tuple[float, float],
    turn: float,
    lead: float,
    radius: float,
    exit_m: float,
    beta: float,
) -> Loop:
    x = u_in
    y = (-u_in[1], u_in[0]) if turn > 0 else (u_in[1], -u_in[0])  # towards the turn

    def at(px: float, py: float) -> tuple[float, float]:
        return (corner[0] + px * x[0] + py * y[0], corner[1] + px * x[1] + py * y[1])

    def bearing(px: float, py: float) -> float:
        return math.atan2(px * x[1] + py * y[1], px * x[0] + py * y[0])

    sb, cb = math.sin(beta), math.cos(beta)
    c1 = at(-lead, -radius)
    c2 = at(-lead + 2.0 * radius * sb, -radius + 2.0 * radius * cb)
    away = Arc(c1, radius, turn < 0, bearing(0.0, 1.0), beta)
    onto = Arc(c2, radius, turn > 0, bearing(-sb, -cb), abs(turn) + beta)
    return Loop(corner, u_in, u_out, lead, exit_m, radius, (away, onto))


def loop_phase(f: Loop, pos: tuple[float, float], state: int, exit_early: float = 0.0) -> int:
    """0 before the loop, 1 and 2 on its arcs, 3 within ``exit_early`` m of its end or past
    it; phases only move on from ``state``."""
    if state == 0:
        rel = (pos[0] - f.corner[0], pos[1] - f.corner[1])
        if rel[0] * f.u_in[0] + rel[1] * f.u_in[1] <= -f.lead:
            return 0
        state = 1
    while state <= len(f.arcs):
        arc = f.arcs[state - 1]
        if arc.progress(pos) < arc.sweep - exit_early / arc.radius:
            return state
        state += 1
    return state
