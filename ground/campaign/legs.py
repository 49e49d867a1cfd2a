"""Per-leg tracking figures of a flight, from the simulator's truth.

Where the metres of cross-track error come from: for each waypoint-to-waypoint leg as
flown (DO_JUMP loops unrolled), the turn onto it, the distance flown from its first
waypoint until the aircraft stays within ``SETTLED_M`` of the line, the cross-track error
on its straight part (more than ``STRAIGHT_MARGIN_M`` from either corner, as the issue
scores it), and the bank-angle and heading wobble there. The campaign's score
(ground/campaign/scoring.py) pools the same legs' straight-part samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from companion.actuators.airframe import load_airframe
from companion.control.flight.controller import TURN_BANK_FRACTION
from companion.control.flight.flight_params import control_params
from companion.control.laws.fillet import corner_arc
from companion.control.mission.executor import RELATIVE_FRAMES
from companion.control.mission.items import MissionItem
from companion.geodesy import STANDARD_GRAVITY as G
from companion.geodesy import LocalFrame
from mavlink_dialect import companion as d

SETTLED_M = 2.0
# A leg's straight part is more than this from either corner, on every leg of every
# airframe, as issue 27 defines it; a leg of 1 km or less has none and is not scored.
# One fixed margin, not one from the airframe's turn: the c172p's turn radius plus its L1
# distance is 300 m (the J3Cub's 180 m), yet on the true state the c172p is within 2 m of
# the new line for good only 400-460 m after a 90° corner and 580-700 m after a 135° one
# (README, "Tracking"), so a margin from the turn counted the end of every roll-out, and
# of the capture after take-off, as tracking error. The campaign's score, the benchmarks
# and the tracking tests all take the straight part from here, so one flight has one
# figure, and airframes are compared on the same stretch of each leg.
STRAIGHT_MARGIN_M = 500.0
MAX_JUMPS = 1000
LEAD_SLACK_M = 150.0
OFF_LINE_M = 150.0  # a leg's first waypoint counts as reached this close to its line


@dataclass(frozen=True)
class Leg:
    """One straight leg as flown: from ``a`` to ``b`` (north/east m), at ``alt_msl``."""

    a: tuple[float, float]
    b: tuple[float, float]
    alt_msl: float
    turn_deg: float  # course change at ``a`` onto this leg (NaN for the first)
    lead_out: float  # m before ``b`` where the executor switches to the next leg
    first: bool = False  # the first of a chain: flown to from elsewhere


@dataclass(frozen=True)
class LegTrack:
    """The truth's samples ``i0:i1``, flown on ``leg``, and where they were on it."""

    leg: Leg
    length_m: float
    i0: int
    i1: int
    along: np.ndarray  # m from ``leg.a`` towards ``leg.b``
    cross: np.ndarray  # m right of the line

    def straight(self) -> np.ndarray:
        """Which of the samples are on the leg's straight part."""
        m = STRAIGHT_MARGIN_M
        return (self.along > m) & (self.along < self.length_m - m)


@dataclass(frozen=True)
class LegFigures:
    """What one leg shows (NaN where it has no samples)."""

    turn_deg: float
    length_m: float
    settled_m: float  # from ``a`` until within SETTLED_M for good
    xt_rms_m: float
    xt_p95_m: float
    xt_mean_m: float
    height_rms_m: float
    bank_sd_deg: float
    heading_sd_deg: float
    samples: int
    track: LegTrack = field(repr=False, compare=False)  # the samples these come from


def airframe_defaults(airframe: str) -> dict[str, float]:
    """The airframe's control parameters at their defaults, by name."""
    return {p.name: p.default for p in control_params(load_airframe(airframe).control)}


def flown_waypoints(items: list[MissionItem]) -> list[tuple[int, MissionItem]]:
    """The waypoints in the order they are flown, DO_JUMP repeats unrolled."""
    out: list[tuple[int, MissionItem]] = []
    jumps: dict[int, int] = {}
    i = 0
    while i < len(items) and len(out) < MAX_JUMPS:
        item = items[i]
        if item.command == d.MAV_CMD_DO_JUMP:
            done, repeats = jumps.get(i, 0), round(item.param2)
            if repeats < 0:
                break  # an endless loop is scored once round
            jumps[i] = done + 1
            i = round(item.param1) if done < repeats else i + 1
            continue
        if item.command == d.MAV_CMD_NAV_WAYPOINT:
            out.append((i, item))
        elif item.command != d.MAV_CMD_DO_CHANGE_SPEED:
            out.append((i, item))  # anything else breaks the chain of straight legs
        i += 1
    return out


def plan_legs(
    items: list[MissionItem], frame: LocalFrame, home_alt: float, turn_radius: float
) -> list[Leg]:
    """The straight legs between consecutive flown waypoints."""
    pts: list[tuple[tuple[float, float], float, bool] | None] = []
    for _, it in flown_waypoints(items):
        alt = it.z + (home_alt if it.frame in RELATIVE_FRAMES else 0.0)
        if it.command == d.MAV_CMD_NAV_WAYPOINT:
            pts.append((frame.ne(it.x / 1e7, it.y / 1e7), alt, True))
        elif it.command == d.MAV_CMD_NAV_RETURN_TO_LAUNCH:
            pts.append(((0.0, 0.0), alt, False))  # turned towards, never a leg's start
        else:
            pts.append(None)
    legs: list[Leg] = []
    for k in range(1, len(pts)):
        here, there = pts[k - 1], pts[k]
        if here is None or there is None or not here[2] or not there[2]:
            continue
        a, b = here[0], there[0]
        before = pts[k - 2] if k >= 2 else None
        after = pts[k + 1] if k + 1 < len(pts) else None
        turn = _turn(before[0], a, b) if before is not None and before[2] else math.nan
        lead = 0.0
        if after is not None:
            out_turn = math.radians(_turn(a, b, after[0]))
            lead = corner_arc(out_turn, turn_radius, math.dist(a, b), math.dist(b, after[0]))[0]
        legs.append(Leg(a, b, there[1], turn, lead, before is None or not before[2]))
    return legs


def _turn(p: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
    c_in = math.atan2(a[1] - p[1], a[0] - p[0])
    c_out = math.atan2(b[1] - a[1], b[0] - a[0])
    return math.degrees(math.remainder(c_out - c_in, math.tau))


def _split(truth: dict[str, np.ndarray], legs: list[Leg], frame: LocalFrame) -> list[LegTrack]:
    """Each leg's share of the truth, the samples split where the executor switches legs."""
    north, east = np.array(
        [frame.ne(a, b) for a, b in zip(truth["lat"], truth["lon"], strict=True)]
    ).T
    start = 0
    out = []
    for leg in legs:
        length = math.dist(leg.a, leg.b)
        u = ((leg.b[0] - leg.a[0]) / length, (leg.b[1] - leg.a[1]) / length)
        along = (north - leg.a[0]) * u[0] + (east - leg.a[1]) * u[1]
        cross = -(north - leg.a[0]) * u[1] + (east - leg.a[1]) * u[0]
        # Skip the flight to the leg's start (the take-off, a loiter) and the part of a
        # sharp turn still far from the new line.
        near = np.abs(cross[start:]) < OFF_LINE_M
        if leg.first:
            near &= along[start:] >= 0.0
        on = np.nonzero(near)[0]
        start = start + int(on[0]) if len(on) else len(north)
        # The leg ends where the executor switches (the lead, give or take what the
        # wind estimate adds to the turn radius), or where the aircraft leaves its line
        # in the second half.
        done = (along[start:] >= length - max(leg.lead_out + LEAD_SLACK_M, 1.0)) | (
            (np.abs(cross[start:]) > OFF_LINE_M) & (along[start:] > length / 2)
        )
        ahead = np.nonzero(done & (along[start:] > 0.0))[0]
        end = start + int(ahead[0]) if len(ahead) else len(north)
        if leg.first:
            # Flown to from elsewhere, the aircraft may cross the line's start more than
            # once (a climb that overflew the first waypoint, and the flight back to it):
            # the leg is the stretch near its line that reaches its end.
            away = np.nonzero(np.abs(cross[start:end]) >= OFF_LINE_M)[0]
            start = start + int(away[-1]) + 1 if len(away) else start
        out.append(LegTrack(leg, length, start, end, along[start:end], cross[start:end]))
        start = end
    return out


def leg_figures(
    truth: dict[str, np.ndarray], legs: list[Leg], frame: LocalFrame
) -> list[LegFigures]:
    """Figures of each leg, the truth's samples split where the executor switches legs."""
    return [_figures(truth, track) for track in _split(truth, legs, frame)]


def _figures(truth: dict[str, np.ndarray], track: LegTrack) -> LegFigures:
    nan = math.nan
    leg, length, along, cross = track.leg, track.length_m, track.along, track.cross
    inside = along < length - STRAIGHT_MARGIN_M
    off = np.nonzero(inside & (np.abs(cross) >= SETTLED_M))[0]
    settled = float(max(along[off[-1]], 0.0)) if len(off) else 0.0
    if not inside.any():
        settled = nan  # too short a leg to say
    straight = track.straight()
    if not straight.any():
        return LegFigures(leg.turn_deg, length, settled, nan, nan, nan, nan, nan, nan, 0, track)
    rows = slice(track.i0, track.i1)
    xt = cross[straight]
    alt = truth["alt"][rows][straight]
    roll = truth["roll"][rows][straight]
    yaw = np.unwrap(truth["yaw"][rows][straight])
    return LegFigures(
        leg.turn_deg, length, settled,
        float(np.sqrt(np.mean(xt**2))), float(np.percentile(np.abs(xt), 95)), float(np.mean(xt)),
        float(np.sqrt(np.mean((alt - leg.alt_msl) ** 2))),
        float(np.degrees(np.std(roll))), float(np.degrees(np.std(yaw))), int(straight.sum()),
        track,
    )  # fmt: skip


def flight_legs(
    truth: dict[str, np.ndarray],
    items: list[MissionItem],
    airframe: str,
    wind_ned: tuple[float, float, float] = (0.0, 0.0, 0.0),
    home_alt: float | None = None,
) -> list[LegFigures]:
    """Per-leg figures of a flight of ``items`` by ``airframe`` in a steady wind
    (``home_alt``: MSL height the relative altitudes count from; the first sample's)."""
    values = airframe_defaults(airframe)
    speed = values["AIRSPEED_CRUISE"] + math.hypot(wind_ned[0], wind_ned[1])
    bank = math.radians(values["ROLL_LIMIT_DEG"]) * TURN_BANK_FRACTION
    radius = speed * speed / (G * math.tan(bank))
    frame = LocalFrame(float(truth["lat"][0]), float(truth["lon"][0]))
    home_alt = float(truth["alt"][0]) if home_alt is None else home_alt
    return leg_figures(truth, plan_legs(items, frame, home_alt, radius), frame)
