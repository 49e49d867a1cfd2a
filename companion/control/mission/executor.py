"""The mission executor: which item is current, what to fly for it, and when it is done.

Pure and replayable: positions in, a ``Setpoint`` and events out. Items as ArduPlane and
PX4 fly them: NAV_TAKEOFF climbs to its altitude; NAV_WAYPOINT is reached inside its
acceptance radius or when the aircraft crosses the line through the waypoint square to
the leg (an overshoot never makes it circle back; the leg after a take-off starts where
the climb ended, so a first waypoint the climb flew past is flown back to); loiters
circle their point (radius param3, negative for counter-clockwise) forever, for param1
seconds or param1 turns once on the circle; NAV_DELAY circles the last point flown to, at
its height, for param1 seconds from its start; NAV_RETURN_TO_LAUNCH ends the mission, reached
as it is begun, and hands the flight to Return (the commander enters that mode, as ArduPlane
and PX4 do: ``control.mission_return``; until it does, or flown without a commander, it
flies home and circles there); DO_CHANGE_SPEED, DO_SET_SERVO (``servo_sets``, for the servo
output), the camera's items, DO_GRIPPER and DO_SET_HOME (``passed_items``) and DO_JUMP act
at once. After the last item the aircraft circles its last point (PX4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from companion.control.laws.fillet import MIN_TURN_RAD, corner_arc
from companion.control.mission import approach
from companion.control.mission.items import (
    HANDED_ITEMS,
    MAX_JUMPS_PER_STEP,
    PASSED_OVER,
    MissionItem,
    change_speed,
    delay_loiter,
    jump_target,
    next_flown,
)
from companion.control.mission.leg_geometry import (
    CircleProgress,
    corner_turn,
    past_point,
    tangent_angle,
)
from companion.control.mission.leg_geometry import distance as _distance
from companion.control.mission.setpoint import Kind, Point, Setpoint
from companion.geodesy import LocalFrame, wrap_pi
from mavlink_dialect import companion as d

RELATIVE_FRAMES = (d.MAV_FRAME_GLOBAL_RELATIVE_ALT, d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT)
ON_CIRCLE = 0.25  # within this fraction of the radius the aircraft counts as circling
TAKEOFF_MARGIN_M = 5.0
LOITER_ALT_MARGIN_M = 5.0  # LOITER_TO_ALT: this close to its height counts as there
TANGENT_WINDOW = math.radians(10.0)  # leave a LOITER_TO_ALT this soon past the tangent point
ESTABLISHED = math.radians(90.0)  # and once it has flown this far round it
# Items a landing's final may start from (``leads_to_landing``).
APPROACH_FROM = {d.MAV_CMD_NAV_WAYPOINT, d.MAV_CMD_NAV_LOITER_TO_ALT}


@dataclass
class ExecutorConfig:
    """Defaults for items that leave them open (ArduPlane's WP_RADIUS, WP_LOITER_RAD, ...)."""

    wp_radius: float = 30.0
    loiter_radius: float = 80.0
    rtl_alt_rel: float = 100.0
    final_slope_max: float = 0.0  # rad: a landing circle descends until its glide is no steeper
    final_flare: tuple[float, float] = (0.0, 0.0)  # (run, height) of that final's flare (m)


@dataclass
class MissionExecutor:
    """Runs a mission from ``start(first)``; ``step()`` once per control cycle."""

    items: list[MissionItem]
    frame: LocalFrame  # centred on home
    home_alt_msl: float
    config: ExecutorConfig = field(default_factory=ExecutorConfig)
    current: int = 0
    speed: float = math.nan
    finished: bool = False
    reached: list[int] = field(default_factory=list)  # items reached since the last drain
    servo_sets: list[tuple[int, int]] = field(default_factory=list)  # (output, µs) passed
    passed_items: list[MissionItem] = field(default_factory=list)  # HANDED_ITEMS passed
    # (MAV_SEVERITY, text) for the operator; a controller's executors share its landing's.
    said: list[tuple[int, str]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.jumps_done: dict[int, int] = {}  # how often each DO_JUMP (by seq) jumped
        self._loiter = CircleProgress()
        self._descending: MissionItem | None = None  # a waypoint flown as a circle down
        self._prev: Point = (0.0, 0.0)
        self._prev_alt = self.home_alt_msl
        self._hold: Setpoint | None = None
        self._home_circled = False  # NAV_RETURN_TO_LAUNCH flown without Return: home reached
        self._turn_radius = 0.0
        self._told: set[int] = set()  # LOITER_TO_ALT items whose circle was said
        # An implicit take-off's height (take_off_first); the waypoint the climb flew past.
        self.climb_to, self._flown_back = math.nan, False

    def start(self, first: int, pos: Point, alt_msl: float, leg_from: Point | None = None) -> None:
        """Begin at item ``first`` from where the aircraft is (or on the leg from ``leg_from``:
        a mission taken up in the air, ``resume.resumed_leg``)."""
        self.current = max(0, min(first, len(self.items)))
        self._prev, self._prev_alt = leg_from or pos, alt_msl
        self.jumps_done.clear()
        self.finished = False
        self._hold, self._home_circled = None, False
        self._loiter, self._descending = CircleProgress(), None
        self.climb_to, self._flown_back = math.nan, False

    def take_off_first(self, alt_msl: float) -> None:
        """On the ground, the next item not a take-off: climb to ``alt_msl`` first as a
        NAV_TAKEOFF would, then fly it (an implicit take-off; the commander says so)."""
        self.climb_to = alt_msl

    def drain_reached(self) -> list[int]:
        """Items reached since the last call (for MISSION_ITEM_REACHED)."""
        out, self.reached = self.reached, []
        return out

    def take_actions(self) -> tuple[list[tuple[int, int]], list[MissionItem]]:
        """The servo sets and the HANDED_ITEMS passed since the last call."""
        out = self.servo_sets, self.passed_items
        self.servo_sets, self.passed_items = [], []
        return out

    def alt_of(self, item: MissionItem) -> float:
        """An item's altitude above MSL."""
        return item.z + (self.home_alt_msl if item.frame in RELATIVE_FRAMES else 0.0)

    def point_of(self, item: MissionItem, pos: Point) -> Point:
        """An item's point in the local frame (lat = lon = 0 means here)."""
        if item.x == 0 and item.y == 0:
            return pos
        return self.frame.ne(item.x / 1e7, item.y / 1e7)

    def step(self, pos: Point, alt_msl: float, t_s: float, turn_radius: float = 0.0) -> Setpoint:
        """The setpoint for now; advances through items that are done. ``turn_radius`` (m)
        lets a waypoint count as reached early enough for the turn to end on the next leg."""
        self._turn_radius = turn_radius
        if not math.isnan(self.climb_to):
            if alt_msl < self.climb_to - TAKEOFF_MARGIN_M:
                return Setpoint(Kind.TAKEOFF, pos, pos, self.climb_to, speed=self.speed)
            self.climb_to = math.nan
            self._climbed(self.current, pos, alt_msl)
        seen: set[tuple[int, tuple[tuple[int, int], ...]]] = set()
        for _ in range(MAX_JUMPS_PER_STEP):
            if self.current >= len(self.items):
                return self._end(pos)
            # Back at an item with every finite jump counter unchanged: an endless loop of
            # DO items that never flies anywhere. End the mission rather than spin.
            state = (self.current, tuple(sorted(self.jumps_done.items())))
            if state in seen:
                return self._end(pos)
            seen.add(state)
            item = self.items[self.current]
            setpoint = self._item(item, pos, alt_msl, t_s)
            if setpoint is not None:
                return setpoint
        return self._end(pos)  # a DO_JUMP loop without a NAV item: stop, don't spin

    def _advance(self, reached: bool, pos: Point, alt: float) -> None:
        if reached:
            self.reached.append(self.items[self.current].seq)
        self.current += 1
        self._prev, self._prev_alt = pos, alt
        self._flown_back = False
        self._loiter, self._descending = CircleProgress(), None

    def _end(self, pos: Point) -> Setpoint:
        if self._hold is None:
            self.finished = True
            self._hold = Setpoint(Kind.CIRCLE, self._prev, self._prev, self._prev_alt,
                                  self.config.loiter_radius, speed=self.speed)  # fmt: skip
        return self._hold

    def _item(self, item: MissionItem, pos: Point, alt: float, t_s: float) -> Setpoint | None:
        """The setpoint of ``item``, or None when it is done (and the next is current)."""
        cmd = item.command
        if cmd == d.MAV_CMD_DO_JUMP:
            self.current = jump_target(item, self.current, self.jumps_done, len(self.items))
            return None
        if cmd in PASSED_OVER:
            if cmd == d.MAV_CMD_DO_CHANGE_SPEED:  # an airspeed or ground speed; -1: no change
                self.speed = change_speed(item, self.speed)
            elif cmd == d.MAV_CMD_DO_SET_SERVO:  # the controller hands it to the servo output
                self.servo_sets.append((round(item.param1), round(item.param2)))
            elif cmd in HANDED_ITEMS:  # and these to its camera, gripper and commander
                self.passed_items.append(item)
            self._advance(False, self._prev, self._prev_alt)
            return None
        if cmd == d.MAV_CMD_NAV_DELAY:  # its seconds count from its start, on the circle or not
            if self._loiter.started_s is None:
                self._loiter.started_s = t_s
            return self._loiter_item(delay_loiter(item, self._prev_alt), pos, alt, t_s)
        if cmd == d.MAV_CMD_NAV_LAND:
            return self._land(item, pos)
        if cmd == d.MAV_CMD_NAV_LOITER_TO_ALT:
            return self._loiter_to_alt(item, pos, alt)
        if cmd == d.MAV_CMD_NAV_TAKEOFF:
            return self._takeoff(item, pos, alt)
        if cmd == d.MAV_CMD_NAV_WAYPOINT:
            return self._waypoint(item, pos, alt)
        if cmd == d.MAV_CMD_NAV_RETURN_TO_LAUNCH:
            return self._return(item, pos, alt)
        return self._loiter_item(item, pos, alt, t_s)

    def _takeoff(self, item: MissionItem, pos: Point, alt: float) -> Setpoint | None:
        target = self.alt_of(item)
        if alt >= target - TAKEOFF_MARGIN_M:
            self._advance(True, self._prev, target)
            self._climbed(self.current, pos, target)
            return None
        return Setpoint(Kind.TAKEOFF, pos, pos, target, speed=self.speed)

    def _climbed(self, nxt: int, pos: Point, alt: float) -> None:
        """The climb has ended at ``pos``: the next leg starts here (ArduPlane), so a first
        waypoint the climb flew past is flown back to (it counted as passed: the next leg
        joined 800 m from it), reached inside its acceptance radius, not a turn's lead (370 m
        before a reversal). Within a turn radius of it, it is passed: no swing round it."""
        item = self.items[nxt] if nxt < len(self.items) else None
        began = self._prev
        self._prev, self._prev_alt = pos, alt
        if item is None or item.command != d.MAV_CMD_NAV_WAYPOINT:
            return
        point = self.point_of(item, pos)
        if _distance(pos, point) <= max(
            item.acceptance_m(self.config.wp_radius), self._turn_radius
        ):
            self._advance(True, point, self.alt_of(item))
        else:
            self._flown_back = past_point(began, point, pos)

    def _waypoint(self, item: MissionItem, pos: Point, alt: float) -> Setpoint | None:
        b = self.point_of(item, pos)
        if self._descending is not None:
            return self._loiter_to_alt(self._descending, pos, alt)
        radius = item.acceptance_m(self.config.wp_radius)
        if _distance(self._prev, b) <= radius:  # a leg from itself (a loiter there, a jump
            self._prev = pos  # back to it) has no finish line: it starts here (ArduPlane)
        if not self._flown_back:
            radius = max(radius, self._turn_lead(self._prev, b))
        if _distance(pos, b) <= radius or past_point(self._prev, b, pos):
            # Too high for the final, or the final turns back on the leg in (a loop): circle down
            # to it first (PX4 and pilots do), else the Cub floated 40 m (the C172: 350 m short).
            land = self._next_point(b) if self.leads_to_landing() else None
            top = self._final_from(b, self.alt_of(item)) + LOITER_ALT_MARGIN_M
            turns_back = approach.turns_back_onto(self._prev, b, land, self._turn_radius)
            if land is not None and (alt > top or turns_back):
                size = max(self.config.loiter_radius, self._turn_radius)
                self._descending = approach.circle_down(item, b, land, pos, size, self.frame)
                if turns_back:
                    self.said.append((d.MAV_SEVERITY_NOTICE, approach.LINE_UP_TEXT % item.seq))
                return self._loiter_to_alt(self._descending, pos, alt)
            self._advance(True, b, self.alt_of(item))
            return None
        return Setpoint(Kind.LINE, self._prev, b, self.alt_of(item), speed=self.speed)

    def _turn_lead(self, a: Point, b: Point) -> float:
        """How far before ``b`` to start turning onto the next leg: R·tan(turn / 2)."""
        nxt = self._next_point(b)
        if nxt is None or self._turn_radius <= 0.0:
            return 0.0
        turn = corner_turn(a, b, nxt)
        if abs(turn) < MIN_TURN_RAD:
            return 0.0
        return corner_arc(turn, self._turn_radius, _distance(a, b), _distance(b, nxt))[0]

    def _next_point(self, here: Point) -> Point | None:
        """Where the leg after the current waypoint goes (None when it is not a leg)."""
        item = self._next_nav()
        if item is None:
            return None
        if item.command == d.MAV_CMD_NAV_RETURN_TO_LAUNCH:
            return (0.0, 0.0)
        if item.command in (d.MAV_CMD_NAV_WAYPOINT, d.MAV_CMD_NAV_LAND):
            return self.point_of(item, here)
        return None

    def leads_to_landing(self) -> bool:
        """Whether the current item is the waypoint or circle the landing's final starts
        from (the next item flown is a NAV_LAND): the controller slows to the approach
        speed and sets the landing flaps on it, as a pilot does before turning final."""
        if self.finished or self.current >= len(self.items):
            return False
        if self.items[self.current].command not in APPROACH_FROM:
            return False
        nxt = self._next_nav()
        return nxt is not None and nxt.command == d.MAV_CMD_NAV_LAND

    def _next_nav(self) -> MissionItem | None:
        """The item flown after the current one, or None."""
        return next_flown(self.items, self.current + 1, self.jumps_done)

    def _return(self, item: MissionItem, pos: Point, alt: float) -> Setpoint:
        """NAV_RETURN_TO_LAUNCH: the mission ends here (the item reached as it is begun);
        home at the return height is what is flown until Return takes over."""
        if not self.finished:
            self.finished = True
            self.reached.append(item.seq)
        home = (0.0, 0.0)
        rtl_alt = self.home_alt_msl + self.config.rtl_alt_rel
        radius = self.config.loiter_radius
        reach = max(radius, self._turn_radius) * 1.5
        if not self._home_circled:
            self._home_circled = _distance(pos, home) <= reach or past_point(self._prev, home, pos)
        if self._home_circled:
            return Setpoint(Kind.CIRCLE, home, home, rtl_alt, radius, speed=self.speed)
        return Setpoint(Kind.LINE, self._prev, home, rtl_alt, speed=self.speed)

    def _land(self, item: MissionItem, pos: Point) -> Setpoint:
        """NAV_LAND: the approach runs from the previous point; the controller lands."""
        point = self.point_of(item, pos)
        return Setpoint(Kind.LAND, self._prev, point, self.alt_of(item), from_alt=self._prev_alt)

    def land_complete(self) -> None:
        """The aircraft has landed and stopped on the current NAV_LAND: the mission is done."""
        if not self.finished:
            self.reached.append(self.items[self.current].seq)
            self.finished = True

    def _loiter_to_alt(self, item: MissionItem, pos: Point, alt: float) -> Setpoint | None:
        """Circle until at the item's height, then (param1 = 1) leave on the tangent that
        points at the next waypoint, so the next leg starts on the circle's edge.

        The controller cannot fly a circle tighter than it turns: a wider one is flown
        through the same exit point, its centre moved off the leg, so the aircraft rolls out
        on the leg (a C172 on QGroundControl's default 75 m landing circle came off its
        215 m one 140 m beside a 380 m final and landed 22 m beside the runway)."""
        centre = self.point_of(item, self._prev)
        given = math.isfinite(item.param2) and item.param2 != 0
        nominal = abs(item.param2) if given else self.config.loiter_radius
        radius = max(nominal, self._turn_radius)
        clockwise = item.param2 >= 0
        target_alt = self.alt_of(item)
        nxt = self._next_point(centre) if item.param1 >= 0.5 else None
        exit_angle = None if nxt is None else tangent_angle(centre, nominal, clockwise, nxt)
        if exit_angle is not None:
            out = (math.cos(exit_angle), math.sin(exit_angle))
            start = (centre[0] + nominal * out[0], centre[1] + nominal * out[1])
            centre = (start[0] - radius * out[0], start[1] - radius * out[1])
            target_alt = self._final_from(start, target_alt)
        if item.seq not in self._told and self._turn_radius > 0.0:  # once, on the circle
            self._told.add(item.seq)
            home, planned_alt = self.home_alt_msl, self.alt_of(item)
            note = approach.circle_note((nominal, planned_alt - home), (radius, target_alt - home))
            self.said += [(d.MAV_SEVERITY_NOTICE, note)] if note else []
        circle = Setpoint(Kind.CIRCLE, centre, centre, target_alt, radius, clockwise, self.speed)
        on_circle = abs(_distance(pos, centre) - radius) <= radius * ON_CIRCLE
        way = 1.0 if clockwise else -1.0
        angle = self._loiter.track(pos, centre, way) if on_circle else self._loiter.off()
        if abs(alt - target_alt) > LOITER_ALT_MARGIN_M or not on_circle:
            return circle
        if exit_angle is None:
            self._advance(True, pos, target_alt)
            return None
        # Flown round the circle for a while (ArduPlane: lined up), not crossing it: an
        # aircraft that came down to the height on its way and met the circle at the
        # exit point flying across it turned final 100° off and landed 54 m beside.
        past = wrap_pi(angle - exit_angle) * way
        if not 0.0 <= past <= TANGENT_WINDOW or self._loiter.swept < ESTABLISHED:
            return circle
        self._advance(True, start, target_alt)
        return None

    def _final_from(self, start: Point, alt: float) -> float:
        land = self._next_nav() if self.config.final_slope_max > 0.0 else None
        if land is None or land.command != d.MAV_CMD_NAV_LAND:
            return alt
        point = self.point_of(land, start)
        steepest, flare = self.config.final_slope_max, self.config.final_flare
        return approach.final_height(alt, start, point, self.alt_of(land), steepest, flare)

    def _loiter_item(
        self, item: MissionItem, pos: Point, alt: float, t_s: float
    ) -> Setpoint | None:
        centre = self.point_of(item, self._prev)
        given = math.isfinite(item.param3) and item.param3 != 0
        radius = abs(item.param3) if given else self.config.loiter_radius
        clockwise = item.param3 >= 0
        target_alt = self.alt_of(item) if item.z or item.frame not in RELATIVE_FRAMES else alt
        circle = Setpoint(Kind.CIRCLE, centre, centre, target_alt, radius, clockwise, self.speed)
        if item.command == d.MAV_CMD_NAV_LOITER_UNLIM:
            return circle
        flown = max(radius, self._turn_radius)  # the controller's circle: never tighter
        state = self._loiter
        if abs(_distance(pos, centre) - flown) > flown * ON_CIRCLE and state.started_s is None:
            return circle  # still getting onto the circle: nothing counts yet
        if state.started_s is None:
            state.started_s = t_s
        state.track(pos, centre)
        if item.command == d.MAV_CMD_NAV_LOITER_TIME:
            done = t_s - state.started_s >= item.param1
        else:  # NAV_LOITER_TURNS
            done = state.swept >= math.tau * max(item.param1, 0.0)
        if done:
            self._advance(True, centre, target_alt)
            return None
        return circle
