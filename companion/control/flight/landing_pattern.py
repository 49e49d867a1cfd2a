"""The landing pattern Land flies when the mission has none, laid inside the geofence.

QGroundControl's fixed-wing landing pattern, as the benchmark plans fly it: a loiter down
to ``HOME_APPROACH_AGL_M``, ``HOME_APPROACH_M`` before the touchdown point, left on the
tangent, the glide to the touchdown point on the runway of this flight's take-off. With a
fence (Fence, companion.control.mission.fence) the first of these whose loiter circle (as
flown: the turn radius when that is wider), approach and rollout keep ``FENCE_MARGIN_M``
inside every inclusion zone and clear of every exclusion zone is flown, as an ArduPlane or
PX4 user lays a landing pattern inside their fence:

1. along the take-off's direction, the loiter on the right (clockwise), then on the left;
2. the other way along the same runway, right then left;
3. all four again with the approach shortened in ``APPROACH_STEP_M`` steps, down to the
   shortest whose glide the airframe still flies (``least_approach``).

Each of these is tried first with the leg from the aircraft to the loiter and a go-around
(the climb-out along the runway to the loiter's height, the turn, the leg back) inside the
fence too, then with the leg only, then alone: a pattern whose go-around or way there
would cross the fence is flown only when no other fits, and said.

None fitting is None: the caller refuses the landing and says so, rather than fly a
pattern that breaches the fence (the fence failsafe would turn the landing into Return).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

from companion.control.mission.items import MissionItem
from companion.control.mission.leg_geometry import tangent_angle
from companion.geodesy import LocalFrame, wrap_pi
from mavlink_dialect import companion as d

Point = tuple[float, float]  # north, east, m about home
Keeps = Callable[[Point, Point, float], bool]  # whether a path and a width breach nothing

HOME_APPROACH_M, HOME_APPROACH_AGL_M, HOME_LOITER_RADIUS_M = 800.0, 50.0, 250.0
HOME_TOUCHDOWN_M = 100.0  # down the runway from where the take-off roll began
# Kept inside the fence by this much: the track's overshoot entering a circle in a gust,
# the tangent left a little late (the fence is judged on the aircraft's position).
FENCE_MARGIN_M = 30.0
# The ground roll judged with the pattern, and how far along the runway a landing the
# other way touches down so that it stops before the take-off roll's start (the C172
# stopped 187 m past the point with the brakes on).
ROLLOUT_M = 250.0
APPROACH_STEP_M = 50.0
# The glide from the loiter's height sinks at the approach airspeed at most this share of
# TECS_SINK_MAX (what the energy controller asks at idle): the rest is for the flare's
# distance, which the glide does not use, and for a tailwind.
GLIDE_SINK_SHARE = 0.8


@dataclass(frozen=True)
class Pattern:
    """One landing pattern: the touchdown point, the landing's course, the loiter."""

    touchdown: Point
    heading: float  # rad, the course along the runway while landing
    centre: Point  # the loiter's
    clockwise: bool  # loiter on the right of the approach, turning right
    approach_m: float  # the loiter's centre abeam this far before the touchdown point
    radius: float = HOME_LOITER_RADIUS_M
    leg_kept: bool = False  # the way there from the aircraft keeps the fence too
    around_kept: bool = False  # and so does a go-around's climb-out and turn back

    def path(self, turn_radius: float) -> list[tuple[Point, Point, float]]:
        """The pattern as flown, as straight paths with their half-width: the loiter (a
        disc: the circle's inside is crossed entering it), the glide from the tangent
        point, the rollout."""
        u = (math.cos(self.heading), math.sin(self.heading))
        angle = tangent_angle(self.centre, self.radius, self.clockwise, self.touchdown)
        exit_ = self.centre
        if angle is not None:
            exit_ = (self.centre[0] + self.radius * math.cos(angle),
                     self.centre[1] + self.radius * math.sin(angle))  # fmt: skip
        stop = (self.touchdown[0] + ROLLOUT_M * u[0], self.touchdown[1] + ROLLOUT_M * u[1])
        circle = (self.centre, self.centre, max(self.radius, turn_radius))
        return [circle, (exit_, self.touchdown, 0.0), (self.touchdown, stop, 0.0)]

    def items(self, frame: LocalFrame) -> list[MissionItem]:
        """The LOITER_TO_ALT and NAV_LAND items the executor flies."""

        def item(seq: int, command: int, point: Point, agl: float, p2: float) -> MissionItem:
            lat, lon = frame.latlon(*point)
            p1, p4 = (1.0, 1.0) if seq == 0 else (0.0, math.nan)  # leave on the tangent
            ll = round(lat * 1e7), round(lon * 1e7)
            frame_id = d.MAV_FRAME_GLOBAL_RELATIVE_ALT
            return MissionItem(seq, frame_id, command, 0, 1, p1, p2, 0.0, p4, *ll, agl)

        radius = self.radius if self.clockwise else -self.radius
        return [
            item(0, d.MAV_CMD_NAV_LOITER_TO_ALT, self.centre, HOME_APPROACH_AGL_M, radius),
            item(1, d.MAV_CMD_NAV_LAND, self.touchdown, 0.0, 0.0),
        ]

    def described(self) -> str:
        """For the operator (within STATUSTEXT's 50 bytes)."""
        course = math.degrees(wrap_pi(self.heading)) % 360.0
        side = "right" if self.clockwise else "left"
        return f"Land: course {course:03.0f}, {self.approach_m:.0f} m final, loiter {side}"


def patterns(base: Point, heading: float, approach_m: float) -> list[Pattern]:
    """The four patterns onto the runway from ``base`` along ``heading``, in the order
    they are preferred (see the module's text)."""
    found = []
    for reverse in (False, True):
        along = HOME_TOUCHDOWN_M + (ROLLOUT_M if reverse else 0.0)
        touchdown = (base[0] + along * math.cos(heading), base[1] + along * math.sin(heading))
        course = heading + math.pi if reverse else heading
        un, ue = math.cos(course), math.sin(course)
        for clockwise in (True, False):
            side = HOME_LOITER_RADIUS_M if clockwise else -HOME_LOITER_RADIUS_M
            centre = (touchdown[0] - approach_m * un - side * ue,
                      touchdown[1] - approach_m * ue + side * un)  # fmt: skip
            found.append(Pattern(touchdown, course, centre, clockwise, approach_m))
    return found


def least_approach(config: Mapping[str, float]) -> float:
    """The shortest approach whose glide from the loiter's height the airframe flies."""
    sink = GLIDE_SINK_SHARE * config["TECS_SINK_MAX"]
    least = HOME_APPROACH_AGL_M * config["TECS_LAND_ARSPD"] / max(sink, 1e-3)
    return min(HOME_APPROACH_M, least)


@dataclass(frozen=True)
class Approach:
    """Where the aircraft starts for the pattern, and how far a go-around climbs out."""

    start: Point
    go_around_m: float


def go_around_run(config: Mapping[str, float]) -> float:
    """How far past the touchdown point a go-around climbs before it turns back to the
    loiter: to the loiter's height at the cruise airspeed and full-throttle climb rate."""
    climb = max(config["TECS_CLMB_MAX"], 0.1)
    return HOME_APPROACH_AGL_M * config["AIRSPEED_CRUISE"] / climb


def _way_there_and_around(p: Pattern, a: Approach, turn_radius: float) -> tuple[list, list]:
    """The leg from the aircraft to the loiter; the go-around's climb-out along the
    runway, its turn (either way: a disc) and the leg back to the loiter."""
    u = (math.cos(p.heading), math.sin(p.heading))
    end = (p.touchdown[0] + a.go_around_m * u[0], p.touchdown[1] + a.go_around_m * u[1])
    around = [(p.touchdown, end, 0.0), (end, end, turn_radius), (end, p.centre, 0.0)]
    return [(a.start, p.centre, 0.0)], around


def choose_pattern(
    base: Point,
    heading: float,
    keeps: Keeps,
    least_m: float,
    turn_radius: float,
    approach: Approach | None = None,
) -> Pattern | None:
    """The first pattern (in the module's order) whose every path ``keeps`` allows with
    ``FENCE_MARGIN_M`` to spare; None when none does down to an approach of ``least_m``.

    With an ``approach``, a pattern whose way there from the aircraft and whose go-around
    also keep the fence is preferred, then one whose way there does, then the pattern
    alone (``leg_kept`` and ``around_kept`` say which: the caller warns of the rest)."""
    tiers = [(True, True), (True, False), (False, False)] if approach else [(False, False)]
    for leg, around in tiers:

        def paths(p: Pattern, leg: bool = leg, around: bool = around) -> list:
            flown = p.path(turn_radius)
            if approach is not None:
                way, go_around = _way_there_and_around(p, approach, turn_radius)
                flown += (way if leg else []) + (go_around if around else [])
            return flown

        found = _first_fitting(base, heading, keeps, least_m, paths)
        if found is not None:
            return replace(found, leg_kept=leg, around_kept=around)
    return None


def _first_fitting(
    base: Point, heading: float, keeps: Keeps, least_m: float, paths: Callable[[Pattern], list]
) -> Pattern | None:
    approach = HOME_APPROACH_M
    while True:
        for pattern in patterns(base, heading, approach):
            if all(keeps(a, b, width + FENCE_MARGIN_M) for a, b, width in paths(pattern)):
                return pattern
        if approach <= least_m:
            return None
        approach = max(least_m, approach - APPROACH_STEP_M)
