"""What each accepted MAV_CMD's parameters may hold, checked before any handler runs.

Every command the link answers has its row here, even an empty one (no parameter read):
the command service refuses to register a handler without one.

A rule names the parameter, its range, whether it is a whole number and whether NaN means
"not given" (the spec gives NaN that meaning in DO_REPOSITION, NAV_LOITER_UNLIM and for
unused parameters, which MAVSDK sends as NaN). Parameters a handler does not read have no
rule and may hold anything. A broken rule is answered MAV_RESULT_DENIED with a status
text that names the field; the handler never sees the command.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from companion.control.mission.items import GLOBAL_FRAMES, MAX_ALT_M
from companion.link.codec import dialect as d
from companion.link.command_service import SET_MODE_MESSAGE, CommandArgs

MAX_MSG_ID = 16_777_215  # MAVLink 2 message ids are 24 bits
MAX_INTERVAL_US = 2**31 - 1


@dataclass(frozen=True)
class Param:
    """One parameter's rule: 1-based index as the spec numbers them."""

    index: int
    name: str
    lo: float
    hi: float
    optional: bool = False  # NaN means "not given"
    whole: bool = False

    def problem(self, value: float) -> str | None:
        if math.isnan(value):
            return None if self.optional else f"{self._label()} is NaN"
        if math.isinf(value):
            return f"{self._label()} is infinite"
        if not self.lo <= value <= self.hi:
            return f"{self._label()} {value:g} outside [{self.lo:g}, {self.hi:g}]"
        if self.whole and value != round(value):
            return f"{self._label()} {value:g} is not a whole number"
        return None

    def _label(self) -> str:
        return f"param{self.index} ({self.name})"


def _lat(i: int) -> Param:
    return Param(i, "latitude", -90.0, 90.0, optional=True)


def _lon(i: int) -> Param:
    return Param(i, "longitude", -180.0, 180.0, optional=True)


def _alt(i: int) -> Param:
    return Param(i, "altitude", -MAX_ALT_M, MAX_ALT_M, optional=True)


def _yaw(i: int) -> Param:
    return Param(i, "yaw", -360.0, 360.0, optional=True)


MSG_ID = Param(1, "message id", 0, MAX_MSG_ID, whole=True)
# PREFLIGHT_CALIBRATION: each parameter 0 or one of PX4's uses of it
# (companion.link.commands.calibration), never NaN, except the airspeed and ESC ones
# (NaN: 0): MAVSDK's Calibration plug-in sends those two as NaN, and every one of its
# calibrations (MAVSDK-Python's calibration.py) was refused with "param6 is NaN".
CALIBRATION = tuple(
    Param(i, name, 0, most, optional=i >= 6, whole=True)
    for i, (name, most) in enumerate((("gyro", 3), ("compass", 1), ("pressure", 1),
                                      ("radio", 2), ("accelerometer", 4), ("airspeed", 2),
                                      ("ESC", 3)), start=1)
)  # fmt: skip
POINT = (_lat(5), _lon(6), _alt(7))

RULES: dict[int, tuple[Param, ...]] = {
    d.MAV_CMD_COMPONENT_ARM_DISARM: (
        Param(1, "arm", 0, 1),
        Param(2, "force", -1e9, 1e9, optional=True, whole=True),
    ),
    d.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN: (Param(1, "autopilot", 0, 3, whole=True),),
    d.MAV_CMD_PREFLIGHT_CALIBRATION: CALIBRATION,
    d.MAV_CMD_PREFLIGHT_STORAGE: (
        Param(1, "parameter storage", 0, 4, whole=True),
        Param(2, "mission storage", -1, 2, optional=True, whole=True),
    ),
    d.MAV_CMD_INJECT_FAILURE: (
        Param(1, "failure unit", 0, 255, whole=True),
        Param(2, "failure type", 0, 255, whole=True),
        Param(3, "instance", 0, 255, optional=True, whole=True),
    ),
    d.MAV_CMD_REQUEST_MESSAGE: (MSG_ID, Param(2, "index", 0, 65535, optional=True, whole=True)),
    d.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES: (),
    d.MAV_CMD_SET_MESSAGE_INTERVAL: (MSG_ID, Param(2, "interval", -1, MAX_INTERVAL_US)),
    d.MAV_CMD_GET_MESSAGE_INTERVAL: (MSG_ID,),
    d.MAV_CMD_GET_HOME_POSITION: (),
    d.MAV_CMD_REQUEST_PROTOCOL_VERSION: (),
    d.MAV_CMD_DO_SET_MODE: (
        Param(1, "base mode", 0, 255, whole=True),
        Param(2, "custom mode", 0, 2**32 - 1, optional=True, whole=True),
        Param(3, "custom sub mode", 0, 2**32 - 1, optional=True, whole=True),
    ),
    d.MAV_CMD_DO_SET_STANDARD_MODE: (Param(1, "standard mode", 0, 255, whole=True),),
    SET_MODE_MESSAGE: (  # integers on the wire, unless a COMMAND_LONG borrows its number
        Param(1, "base mode", 0, 255, whole=True),
        Param(2, "custom mode", 0, 2**32 - 1, whole=True),
    ),
    d.MAV_CMD_MISSION_START: (
        Param(1, "first item", -1, 65535, optional=True, whole=True),  # -1: the item kept
        Param(2, "last item", 0, 65535, optional=True, whole=True),
    ),
    d.MAV_CMD_NAV_RETURN_TO_LAUNCH: (),
    d.MAV_CMD_DO_SET_MISSION_CURRENT: (
        Param(1, "item", -1, 65535, whole=True),
        Param(2, "reset", 0, 1, optional=True, whole=True),
    ),
    d.MAV_CMD_DO_CHANGE_SPEED: (
        Param(1, "speed type", 0, 3, whole=True),
        Param(2, "speed", -2, 1000),  # -1 no change, -2 the default; m/s
        Param(3, "throttle", -2, 100, optional=True),  # -1 no change, -2 the default; %
    ),
    d.MAV_CMD_DO_PAUSE_CONTINUE: (Param(1, "continue", 0, 1, whole=True),),
    d.MAV_CMD_DO_FENCE_ENABLE: (Param(1, "enable", 0, 2, whole=True),),
    # The Mini SSC's eight outputs, numbered from 1 as ArduPilot's SERVOn; the pulse the
    # card can put out (its 90° range).
    d.MAV_CMD_DO_SET_SERVO: (
        Param(1, "instance", 1, 8, whole=True),
        Param(2, "PWM", 1000, 2000, whole=True),
    ),
    # A payload gripper on a servo output (companion.control.mission.gripper): one, so
    # which (param1, MAVSDK's instance) is not read.
    d.MAV_CMD_DO_GRIPPER: (
        Param(1, "instance", 0, 255, optional=True, whole=True),
        Param(2, "action", 0, 1, whole=True),
    ),
    # Actuator sets 1-6 (companion.control.mission.actuator_sets): -1..1, NaN leaves one;
    # the index must be 0 (the flight controller refuses another with the reason).
    d.MAV_CMD_DO_SET_ACTUATOR: (
        *(Param(n, f"actuator {n}", -1, 1, optional=True) for n in range(1, 7)),
        Param(7, "index", 0, 255, optional=True, whole=True),
    ),
    # A camera on a servo output (companion.control.mission.camera): a distance between
    # photos (0 stops), an interval and a count, one photo (DIGICAM_CONTROL's param5 1).
    d.MAV_CMD_DO_SET_CAM_TRIGG_DIST: (
        Param(1, "distance", 0, 1e4),
        Param(3, "trigger now", 0, 1, optional=True, whole=True),
    ),
    d.MAV_CMD_IMAGE_START_CAPTURE: (
        Param(2, "interval", 0, 3600, optional=True),
        Param(3, "total images", 0, 1e6, optional=True, whole=True),
    ),
    d.MAV_CMD_IMAGE_STOP_CAPTURE: (),
    d.MAV_CMD_DO_DIGICAM_CONTROL: (Param(5, "shoot", 0, 1, optional=True, whole=True),),
    d.MAV_CMD_DO_GO_AROUND: (Param(1, "altitude", -MAX_ALT_M, MAX_ALT_M, optional=True),),
    d.MAV_CMD_DO_REPOSITION: (
        Param(1, "ground speed", -1, 1000, optional=True),
        Param(3, "loiter radius", -1e5, 1e5, optional=True),
        _yaw(4),
        *POINT,
    ),
    d.MAV_CMD_NAV_LOITER_UNLIM: (Param(3, "radius", -1e5, 1e5, optional=True), _yaw(4), *POINT),
    d.MAV_CMD_DO_SET_HOME: (
        Param(1, "use current", 0, 1, optional=True, whole=True),
        _yaw(4),
        *POINT,
    ),
    d.MAV_CMD_NAV_TAKEOFF: (Param(1, "pitch", -90, 90, optional=True), _yaw(4), *POINT),
    d.MAV_CMD_NAV_LAND: (_yaw(4), *POINT),
    d.MAV_CMD_DO_ORBIT: (
        Param(1, "radius", -1e4, 1e4, optional=True),
        Param(2, "velocity", -1e3, 1e3, optional=True),
        Param(4, "orbits", 0, 1e6, optional=True),
        *POINT,
    ),
}


def _home_needs_a_point(args: CommandArgs) -> str | None:
    if whole_or(args.params[0], 0) == 1:
        return None
    if any(math.isnan(v) for v in args.params[4:7]):
        return "param5-7 (home position) not given"
    if args.params[4] == 0 and args.params[5] == 0:
        # Every parameter 0 (a custom action, a default): read as a place, home would be in
        # the Gulf of Guinea at sea level, and Return and the height floor would follow it.
        return "param5-6 (home position) 0, 0 is no home"
    return None


EXTRA_CHECKS: dict[int, Callable[[CommandArgs], str | None]] = {
    d.MAV_CMD_DO_SET_HOME: _home_needs_a_point,
}


POSITION_COMMANDS = frozenset(
    {
        d.MAV_CMD_DO_REPOSITION,
        d.MAV_CMD_NAV_LOITER_UNLIM,
        d.MAV_CMD_DO_SET_HOME,
        d.MAV_CMD_NAV_TAKEOFF,
        d.MAV_CMD_NAV_LAND,
        d.MAV_CMD_DO_ORBIT,
    }
)


def refusal(args: CommandArgs) -> str | None:
    """Why this command's parameters are refused, or None if they may go to its handler."""
    if args.is_int and args.command in POSITION_COMMANDS and args.frame not in GLOBAL_FRAMES:
        return f"frame {args.frame} not supported (global frames only)"
    for rule in RULES[args.command]:  # a handler exists only for a command with a rule
        problem = rule.problem(args.params[rule.index - 1])
        if problem is not None:
            return problem
    extra = EXTRA_CHECKS.get(args.command)
    return extra(args) if extra is not None else None


def whole_or(value: float, default: int) -> int:
    """A checked optional whole-number parameter: its value, or ``default`` when NaN."""
    return default if math.isnan(value) else round(value)
