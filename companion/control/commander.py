"""The vehicle's mode, home and guided target: who may fly what, and when.

Pure: commands and navigation in, decisions and a ``VehicleStatus`` out. The
``vehicle.commander`` plug-in wraps it; the link reports what it decides.
Rules (as PX4 and ArduPilot have them): MISSION needs a stored mission; RTL needs a home;
GUIDED and LOITER need a position (or a given point); LAND (PX4's Land: the mission's
landing from its DO_LAND_START, else back onto the take-off runway at home) needs one of
the two; home is the first valid position, and is set again at arming.
A reposition without a point (QGroundControl's Pause and Change altitude, PX4's
DO_REPOSITION with NaN latitude/longitude) keeps the point being flown to, or circles here,
at the altitude given (or the present one).

Return flies to the nearest rally point instead of home when there is one and it is
nearer (``companion.control.mission.rally``), chosen as it is entered and kept as its
target; it says which on ``notices``.

No command sends the aircraft below a safe height (``GUIDED_ALT_MIN`` above home: the
vehicle has no terrain data, so home's height stands for the ground's). A target given
under it is refused with the reason; a target without an altitude is flown at the present
altitude, or at that minimum if the aircraft is lower.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from companion.control.flight_state import FlightState
from companion.control.ground_rules import AIRBORNE_ONLY, refusal
from companion.control.inputs import position_usable
from companion.control.mission.items import MAX_ALT_M
from companion.control.mission.rally import RALLY_PARAMS, RallyPoints, choose_return
from companion.control.modes import INITIAL_MODE
from companion.messages import (
    CommandId,
    CommandResult,
    FlightMode,
    LandPhase,
    NavFlags,
    NavState,
    VehicleCommand,
    VehicleStatus,
)
from companion.params import ParamDecl

MAX_RADIUS_M = 10_000.0  # an orbit wider than this is a mistake, not a plan
MIN_ALT_PARAM = "GUIDED_ALT_MIN"
COMMANDER_PARAMS = (
    ParamDecl(MIN_ALT_PARAM, 30.0, 0.0, 1000.0, "m",
              "least height above home a command may send the aircraft to (go to, hold, "
              "change altitude, orbit, take-off)"),
)  # fmt: skip


@dataclass(frozen=True)
class Decision:
    """A command's outcome, and why when it is refused."""

    result: CommandResult
    reason: str = ""


ACCEPTED = Decision(CommandResult.ACCEPTED)
MODE_COMMANDS = frozenset(
    {
        CommandId.SET_MODE,
        CommandId.MISSION_START,
        CommandId.RETURN_TO_LAUNCH,
        CommandId.REPOSITION,
        CommandId.LOITER,
        CommandId.SET_HOME,
        CommandId.TAKEOFF,
        CommandId.ORBIT,
        CommandId.GO_AROUND,
        CommandId.CHANGE_SPEED,
        CommandId.SET_MISSION_CURRENT,
    }
)
# The mode commands that choose what the aircraft flies (not a speed, home or mission item):
# an operator's choice, which a failsafe's later recovery must not undo.
MODE_CHOICES = MODE_COMMANDS - {
    CommandId.SET_HOME,
    CommandId.CHANGE_SPEED,
    CommandId.SET_MISSION_CURRENT,
    CommandId.GO_AROUND,
}
# Commands that fly a mode a fixed wing cannot fly from the runway.
_AIRBORNE_COMMANDS = {
    CommandId.RETURN_TO_LAUNCH: FlightMode.RTL,
    CommandId.REPOSITION: FlightMode.GUIDED,
    CommandId.LOITER: FlightMode.LOITER,
    CommandId.ORBIT: FlightMode.LOITER,
}
NO_POINT = (math.nan, math.nan, math.nan)
LANDING_PHASES = (LandPhase.APPROACH, LandPhase.FLARE)  # a go-around can still be flown


class Commander:
    """Mode state machine; ``mission_count`` says how many mission items are stored,
    ``mission_lands`` whether the stored mission has a DO_LAND_START and
    ``mission_takeoff`` which item is its first take-off (-1: none); ``rally_params`` the
    live values of ``RALLY_PARAMS``, ``rally`` the rally points Return may fly to."""

    def __init__(
        self,
        mission_count: Callable[[], int],
        mission_lands: Callable[[], bool] = lambda: False,
        min_height: Callable[[], float] = lambda: COMMANDER_PARAMS[0].default,
        mission_takeoff: Callable[[], int] = lambda: -1,
        rally_params: Mapping[str, float] | None = None,
    ) -> None:
        self.mission_count = mission_count
        self.mission_lands = mission_lands
        self.min_height = min_height
        self.mission_takeoff = mission_takeoff
        self.rally_params = rally_params or {p.name: p.default for p in RALLY_PARAMS}
        self.rally = RallyPoints()
        self.notices: list[str] = []  # what the operator is told of a choice made
        self.mode = INITIAL_MODE
        self.armed = False
        self.home: tuple[float, float, float] | None = None
        self.target = NO_POINT
        self.radius = math.nan
        self.mission_first = 0
        self.changes = 0
        self.position: tuple[float, float, float] | None = None
        self.go_arounds = 0
        self.mission_jumps, self.mission_jump_to = 0, -1  # set-currents accepted, the last
        self.speed = math.nan  # DO_CHANGE_SPEED's airspeed (NaN: none), as PX4's navigator
        self.land_phase = 0  # the flight controller's, from its status
        self.landed = False  # armed and the flight controller says it stands on the ground
        self.rejected_nav = 0  # solutions whose "valid" position was not a place

    def on_nav(self, nav: NavState) -> bool:
        """Track the position; set home from the first fix while disarmed.

        False (and counted in ``rejected_nav``) when the solution says its position is
        valid but it is not a place on Earth: it is neither home nor judged by failsafes.
        """
        if not nav.flags & NavFlags.POSITION_VALID:
            return True
        if not position_usable(nav):
            self.rejected_nav += 1
            return False
        self.position = (nav.lat_deg, nav.lon_deg, nav.alt_msl_m)
        if self.home is None:  # armed before the first fix: home is where that fix is
            self.home = self.position
        return True

    def on_armed(self, armed: bool) -> None:
        """Arming sets home where the aircraft is (the place it will return to)."""
        if armed and not self.armed and self.position is not None:
            self.home = self.position
        if not armed:
            self.speed = math.nan  # the flight is over: the next flies the cruise airspeed
        self.armed = armed

    def handle(self, cmd: VehicleCommand) -> Decision | None:
        """Act on a mode command; None for commands that are not the commander's."""
        kind = cmd.command
        p = list(cmd.param)
        if kind == CommandId.SET_MODE:
            try:
                mode = FlightMode(_whole(p[0], -1))
            except ValueError:
                return Decision(CommandResult.DENIED, f"unknown mode {p[0]:g}")
            return self._grounded(mode) or self._enter(mode)
        if (grounded := self._grounded(_AIRBORNE_COMMANDS.get(kind))) is not None:
            return grounded
        if kind == CommandId.MISSION_START:
            return self._mission_start(_whole(p[0], -1))
        if kind == CommandId.SET_MISSION_CURRENT:
            return self._set_current(_whole(p[0], -1))
        if kind == CommandId.RETURN_TO_LAUNCH:
            return self._enter(FlightMode.RTL)
        if kind in (CommandId.REPOSITION, CommandId.LOITER, CommandId.ORBIT):
            return self._go_to(kind, p)
        if kind == CommandId.TAKEOFF:
            return self._takeoff(p[2])
        if kind == CommandId.SET_HOME:
            return self._set_home(p)
        if kind == CommandId.CHANGE_SPEED:
            return self._change_speed(p[0])
        if kind == CommandId.GO_AROUND:
            if self.land_phase not in LANDING_PHASES:
                return Decision(CommandResult.DENIED, "Go around: not landing")
            self.go_arounds += 1
            return ACCEPTED
        return None

    def _mission_start(self, first: int) -> Decision:
        """Mission mode; param1 as PX4 takes it: an item (0 or more) starts there, as a
        set-current would, anything else the item set current last (or left at)."""
        decision = self._enter(FlightMode.MISSION)
        if decision.result == CommandResult.ACCEPTED and 0 <= first < self.mission_count():
            self._jump(first)
        return decision

    def _set_current(self, seq: int) -> Decision:
        """MISSION_SET_CURRENT / DO_SET_MISSION_CURRENT: a mission flying goes to item
        ``seq`` at once, any other mode enters the mission there. Refused beyond the
        mission, and on the ground beyond its take-off (that would never be flown)."""
        count, takeoff = self.mission_count(), self.mission_takeoff()
        if not 0 <= seq < count:
            what = "no mission stored" if count == 0 else f"the mission has {count} items"
            return Decision(CommandResult.DENIED, f"Set mission item: no item {seq} ({what})")
        if (not self.armed or self.landed) and 0 <= takeoff < seq:
            reason = f"Set mission item: {seq} skips the take-off (item {takeoff}) on the ground"
            return Decision(CommandResult.DENIED, reason)
        self._jump(seq)
        return ACCEPTED

    def _jump(self, seq: int) -> None:
        self.mission_first, self.mission_jump_to = seq, seq
        self.mission_jumps += 1

    def _grounded(self, mode: FlightMode | None) -> Decision | None:
        """Refused: a mode that cannot fly from the runway, asked for armed on the ground
        (``companion.control.ground_rules``)."""
        if mode in AIRBORNE_ONLY and self.armed and self.landed:
            return Decision(CommandResult.DENIED, refusal(mode))
        return None

    def _go_to(self, kind: CommandId, p: list[float]) -> Decision:
        if not _usable_point(p[0], p[1], p[2]):
            return Decision(CommandResult.DENIED, "Go to: position out of range")
        radius = p[3] if kind == CommandId.ORBIT else math.nan
        if not (math.isnan(radius) or 0 < abs(radius) <= MAX_RADIUS_M):
            return Decision(CommandResult.DENIED, "Orbit: radius out of range")
        names = {CommandId.REPOSITION: "Go to", CommandId.LOITER: "Hold"}
        low = self._too_low(names.get(kind, "Orbit"), p[2])
        if low is not None:
            return low
        if kind == CommandId.REPOSITION and math.isnan(p[0]) and math.isnan(p[1]):
            return self._pause(p[2])
        mode = FlightMode.GUIDED if kind == CommandId.REPOSITION else FlightMode.LOITER
        return self._enter(mode, (p[0], p[1], p[2]), abs(radius))

    def floor(self) -> float:
        """The least altitude (AMSL) a command may ask for; -inf before there is a home."""
        if self.home is None:
            return -math.inf
        return self.home[2] + max(0.0, self.min_height())

    def _too_low(self, what: str, alt: float) -> Decision | None:
        """Refuse an altitude under the floor (NaN: not given, never too low)."""
        if not alt < self.floor():
            return None
        assert self.home is not None
        height, least = alt - self.home[2], self.floor() - self.home[2]
        reason = f"{what}: {height:.0f} m above home is below {MIN_ALT_PARAM} {least:.0f} m"
        return Decision(CommandResult.DENIED, reason)

    def _pause(self, alt: float) -> Decision:
        """Keep flying to (or circling) the present point, else circle here; new height."""
        if self.mode in (FlightMode.GUIDED, FlightMode.LOITER) and math.isfinite(self.target[0]):
            lat, lon, old_alt = self.target
            return self._enter(self.mode, (lat, lon, alt if math.isfinite(alt) else old_alt))
        return self._enter(FlightMode.LOITER, (math.nan, math.nan, alt), self.radius)

    def _takeoff(self, alt: float) -> Decision:
        if not math.isnan(alt) and not (math.isfinite(alt) and abs(alt) <= MAX_ALT_M):
            return Decision(CommandResult.DENIED, "Takeoff: altitude out of range")
        low = self._too_low("Takeoff", alt)
        if low is not None:
            return low
        decision = self._enter(FlightMode.TAKEOFF)
        if decision.result == CommandResult.ACCEPTED:
            self.target = (math.nan, math.nan, alt)
        return decision

    def _change_speed(self, speed: float) -> Decision:
        """Fly ``speed`` m/s airspeed (NaN: the default again) until the mode changes (the
        link has checked it against the airframe's limits, the controller bounds it)."""
        if not (math.isnan(speed) or (math.isfinite(speed) and speed > 0)):
            return Decision(CommandResult.DENIED, f"Change speed: {speed:g} m/s")
        self.speed = speed
        return ACCEPTED

    def failsafe(self, mode: FlightMode) -> Decision:
        """A failsafe's mode change (Return, or Loiter where the aircraft is)."""
        return self._enter(mode)

    def _enter(
        self, mode: FlightMode, point: tuple[float, ...] | None = None, radius: float = math.nan
    ) -> Decision:
        if mode == FlightMode.LAND and not self.mission_lands() and self.home is None:
            return Decision(CommandResult.DENIED, "Land: no home runway yet, no mission landing")
        if mode == FlightMode.MISSION and self.mission_count() == 0:
            return Decision(CommandResult.DENIED, "Mission: no mission stored")
        if mode == FlightMode.RTL and self.home is None:
            return Decision(CommandResult.DENIED, "Return: no home position yet")
        if mode in (FlightMode.GUIDED, FlightMode.LOITER):
            target = self._target(point)
            if target is None:
                name = "Go to" if mode == FlightMode.GUIDED else "Hold"
                return Decision(CommandResult.DENIED, f"{name}: no position yet")
            self.target, self.radius = target, radius
        elif mode == FlightMode.RTL:
            self.target, self.radius = self._return_target(), math.nan
        else:
            self.target, self.radius = NO_POINT, math.nan
        # A speed asked for holds in its mode (PX4's navigator resets it on a change of mode
        # but for the loiter a take-off ends in).
        if mode != self.mode and not (
            self.mode == FlightMode.TAKEOFF and mode == FlightMode.LOITER
        ):
            self.speed = math.nan
        # Every accepted command counts, not only a change of mode: a second go-to in
        # Guided is a new target the controller must turn to.
        self.changes += 1
        self.mode = mode
        return ACCEPTED

    def take_notices(self) -> list[str]:
        """What the operator is to be told since the last call (then forgotten)."""
        notices, self.notices = self.notices, []
        return notices

    def _return_target(self) -> tuple[float, float, float]:
        """Return's rally point (NO_POINT: home), from where the aircraft is now."""
        if self.home is None or self.position is None:
            return NO_POINT
        here = (self.position[0], self.position[1])
        choice = choose_return(self.rally, here, self.home, self.floor(), self.rally_params)
        if choice.text:
            self.notices.append(choice.text)
        return choice.point or NO_POINT

    def _target(self, point: tuple[float, ...] | None) -> tuple[float, float, float] | None:
        here = self.position
        # No altitude given: the present one, but never under the floor (a hold asked for
        # just after take-off circles at the safe height, not at 10 m).
        present = max(here[2], self.floor()) if here is not None else math.nan
        if point is not None and math.isfinite(point[0]) and math.isfinite(point[1]):
            alt = point[2] if math.isfinite(point[2]) else present
            return (point[0], point[1], alt)
        if here is None:
            return None
        if point is not None and math.isfinite(point[2]):
            return (here[0], here[1], point[2])  # here, at the height asked for
        return (here[0], here[1], present)

    def _set_home(self, p: list[float]) -> Decision:
        if _whole(p[0], 0) == 1:
            if self.position is None:
                return Decision(CommandResult.DENIED, "Home: no position yet")
            self.home = self.position
        elif all(math.isfinite(v) for v in p[4:7]) and _usable_point(p[4], p[5], p[6]):
            self.home = (p[4], p[5], p[6])
        else:
            return Decision(CommandResult.DENIED, "Home: bad position")
        return ACCEPTED

    def snapshot(self) -> FlightState:
        """What a restarted commander needs to carry this flight on."""
        return FlightState(
            self.armed, int(self.mode), self.home, self.target, self.radius,
            self.mission_first, self.changes, self.go_arounds, self.mission_jumps,
            self.mission_jump_to, self.speed,
        )  # fmt: skip

    def restore(self, saved: FlightState) -> None:
        """Carry on the flight ``saved`` describes (armed, as the caller has judged)."""
        self.mode, self.home = FlightMode(saved.mode), saved.home or self.home
        self.target, self.radius = saved.target, saved.radius
        # A mission goes on from the item it was flying to: a controller started after
        # this (its process restarted too) takes the mission up there, not at item 0.
        self.mission_first = saved.mission_seq
        self.changes, self.go_arounds = saved.changes, saved.go_arounds
        self.mission_jumps, self.mission_jump_to = saved.mission_jumps, saved.mission_jump_to
        self.armed, self.speed = True, saved.speed  # a DO_CHANGE_SPEED holds in its mode

    def status(self, t_us: int) -> VehicleStatus:
        """What the link and the controller are told."""
        msg = VehicleStatus(t_us=t_us, mode=int(self.mode), armed=int(self.armed))
        msg.home_valid = int(self.home is not None)
        msg.home_lat_deg, msg.home_lon_deg, msg.home_alt_msl_m = self.home or (math.nan,) * 3
        msg.target_lat_deg, msg.target_lon_deg, msg.target_alt_msl_m = self.target
        msg.target_radius_m = self.radius
        msg.mission_first, msg.changes = self.mission_first, self.changes
        msg.go_arounds, msg.speed_m_s = self.go_arounds, self.speed
        msg.mission_jumps, msg.mission_jump_to = self.mission_jumps, self.mission_jump_to
        return msg


def _whole(value: float, default: int) -> int:
    """A whole-number command parameter; ``default`` for NaN or infinity (never a crash)."""
    return round(value) if math.isfinite(value) else default


def _usable_point(lat: float, lon: float, alt: float) -> bool:
    """NaN means "not given"; anything else must be a place on Earth at a sane height."""
    if math.isinf(lat) or math.isinf(lon) or math.isinf(alt):
        return False
    in_range = not (abs(lat) > 90 or abs(lon) > 180 or abs(alt) > MAX_ALT_M)
    return in_range  # NaN compares False, so a NaN coordinate passes as "not given"
