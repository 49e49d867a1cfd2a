"""Mission items (MISSION_ITEM_INT fields) and what the vehicle can fly.

Only what the executor flies is accepted: no terrain frames (it has no terrain data), so
such a plan is refused at upload with the matching MAV_MISSION_RESULT instead of being
skipped in flight. Items that aim or set up what the vehicle does not carry (a gimbal, a
video or MAVLink camera) and a multicopter's yaw are accepted and passed over, as PX4 takes
them from QGroundControl's Plan view: the plan flies, and the operator is told at upload
(``not_carried_note``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, replace
from typing import Any

from mavlink_dialect import companion as d

MISSION_TYPES = (d.MAV_MISSION_TYPE_MISSION, d.MAV_MISSION_TYPE_FENCE, d.MAV_MISSION_TYPE_RALLY)

NAV_COMMANDS = frozenset(
    {
        d.MAV_CMD_NAV_WAYPOINT,
        d.MAV_CMD_NAV_LOITER_UNLIM,
        d.MAV_CMD_NAV_LOITER_TURNS,
        d.MAV_CMD_NAV_LOITER_TIME,
        d.MAV_CMD_NAV_RETURN_TO_LAUNCH,
        d.MAV_CMD_NAV_TAKEOFF,
        d.MAV_CMD_NAV_LOITER_TO_ALT,
        d.MAV_CMD_NAV_LAND,
        d.MAV_CMD_NAV_DELAY,
    }
)
# What a survey, a waypoint's camera section and a landing pattern's camera stop say to a
# camera on a servo output (companion.control.mission.camera).
CAMERA_ITEMS = frozenset(
    {
        d.MAV_CMD_DO_SET_CAM_TRIGG_DIST,
        d.MAV_CMD_IMAGE_START_CAPTURE,
        d.MAV_CMD_IMAGE_STOP_CAPTURE,
        d.MAV_CMD_DO_DIGICAM_CONTROL,
    }
)
CAMERA_STOPS = frozenset({d.MAV_CMD_VIDEO_STOP_CAPTURE})  # no video camera to stop
# What QGroundControl's Plan view offers a PX4 plane for a gimbal (regions of interest, mount
# and gimbal-manager angles), a video or MAVLink camera (its mode, zoom, focus, video) and a
# multicopter's yaw: nothing on board acts on them (photos go through CAM1_*).
NOT_CARRIED = frozenset(
    {
        d.MAV_CMD_DO_SET_ROI_LOCATION,
        d.MAV_CMD_DO_SET_ROI_WPNEXT_OFFSET,
        d.MAV_CMD_DO_SET_ROI_NONE,
        d.MAV_CMD_DO_SET_ROI,
        d.MAV_CMD_DO_MOUNT_CONFIGURE,
        d.MAV_CMD_DO_MOUNT_CONTROL,
        d.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW,
        d.MAV_CMD_DO_GIMBAL_MANAGER_CONFIGURE,
        d.MAV_CMD_SET_CAMERA_MODE,
        d.MAV_CMD_SET_CAMERA_ZOOM,
        d.MAV_CMD_SET_CAMERA_FOCUS,
        d.MAV_CMD_VIDEO_START_CAPTURE,
        d.MAV_CMD_CONDITION_YAW,
    }
)
# Markers, camera stops and the above: nothing to fly (DO_LAND_START only marks where a
# landing begins).
SKIPPED = CAMERA_STOPS | NOT_CARRIED | {d.MAV_CMD_DO_LAND_START}
MAX_JUMPS_PER_STEP = 100_000  # a hard stop, far beyond any real mission's DO items
# What the controller's plug-in carries out as the mission passes them: the camera's items,
# a payload gripper's (mission/gripper.py), a new home (DO_SET_HOME, as ArduPlane and PX4
# take it in a mission: the aircraft's place, param1 1, or the item's).
HANDED_ITEMS = CAMERA_ITEMS | {
    d.MAV_CMD_DO_GRIPPER, d.MAV_CMD_DO_SET_HOME, d.MAV_CMD_DO_SET_ACTUATOR,
}  # fmt: skip
# DO items that act at once and fly nowhere: a speed, a servo output (a payload release),
# a camera's photos, a gripper, a new home, actuator sets (mission/actuator_sets.py).
ACTIONS = frozenset({d.MAV_CMD_DO_CHANGE_SPEED, d.MAV_CMD_DO_SET_SERVO}) | HANDED_ITEMS
PASSED_OVER = SKIPPED | ACTIONS  # done as they are reached: the next item is current at once
DO_COMMANDS = PASSED_OVER | {d.MAV_CMD_DO_JUMP}
SERVO_OUTPUTS = range(1, 9)  # DO_SET_SERVO's param1: the Mini SSC's eight, from 1
SERVO_PULSES_US = (1000.0, 2000.0)  # and param2: what the card puts out (its 90° range)
SUPPORTED = {
    d.MAV_MISSION_TYPE_MISSION: NAV_COMMANDS | DO_COMMANDS,
    d.MAV_MISSION_TYPE_FENCE: frozenset(
        {
            d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION,
            d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_EXCLUSION,
            d.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION,
            d.MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION,
            d.MAV_CMD_NAV_FENCE_RETURN_POINT,
        }
    ),
    d.MAV_MISSION_TYPE_RALLY: frozenset({d.MAV_CMD_NAV_RALLY_POINT}),
}
GLOBAL_FRAMES = frozenset(
    {
        d.MAV_FRAME_GLOBAL,
        d.MAV_FRAME_GLOBAL_INT,
        d.MAV_FRAME_GLOBAL_RELATIVE_ALT,
        d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
    }
)
POSITIONLESS = (
    frozenset(
        {
            d.MAV_CMD_NAV_RETURN_TO_LAUNCH,
            d.MAV_CMD_DO_CHANGE_SPEED,
            d.MAV_CMD_DO_SET_SERVO,
            d.MAV_CMD_DO_GRIPPER,
            d.MAV_CMD_DO_SET_ACTUATOR,
            d.MAV_CMD_DO_JUMP,
            d.MAV_CMD_DO_LAND_START,
            d.MAV_CMD_NAV_DELAY,  # circles the last point flown to (``delay_loiter``)
        }
    )
    | CAMERA_STOPS
    | CAMERA_ITEMS
    | NOT_CARRIED  # a region of interest's position is never flown to
)


# Parameters (1-based) the executor or the fence reads as numbers: NaN there is refused.
# Elsewhere NaN means "not given" (yaw, unused parameters); infinity is refused everywhere.
NEEDS_NUMBER = {
    d.MAV_CMD_DO_JUMP: (1, 2),
    d.MAV_CMD_DO_SET_SERVO: (1, 2),
    d.MAV_CMD_DO_GRIPPER: (2,),
    d.MAV_CMD_DO_SET_HOME: (1,),
    d.MAV_CMD_DO_SET_CAM_TRIGG_DIST: (1,),
    d.MAV_CMD_IMAGE_START_CAPTURE: (2, 3),
    d.MAV_CMD_NAV_LOITER_TURNS: (1,),
    d.MAV_CMD_NAV_LOITER_TIME: (1,),
    d.MAV_CMD_NAV_DELAY: (1,),
    d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION: (1,),
    d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_EXCLUSION: (1,),
    d.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION: (1,),
    d.MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION: (1,),
}
INVALID_PARAM = (
    d.MAV_MISSION_INVALID_PARAM1,
    d.MAV_MISSION_INVALID_PARAM2,
    d.MAV_MISSION_INVALID_PARAM3,
    d.MAV_MISSION_INVALID_PARAM4,
    d.MAV_MISSION_INVALID_PARAM5_X,
    d.MAV_MISSION_INVALID_PARAM6_Y,
)
MAX_ALT_M = 100_000.0  # above this an altitude is a broken input, not a target
MAX_PARAM = 1e7  # no parameter of a supported item means anything beyond this


@dataclass(frozen=True)
class MissionItem:
    """One item, as MISSION_ITEM_INT carries it (x, y in degrees × 1e7)."""

    seq: int
    frame: int
    command: int
    current: int
    autocontinue: int
    param1: float
    param2: float
    param3: float
    param4: float
    x: int
    y: int
    z: float
    mission_type: int = 0

    @classmethod
    def from_message(cls, msg: Any) -> MissionItem:  # a pymavlink message: untyped
        """From MISSION_ITEM_INT, or legacy MISSION_ITEM (float degrees)."""
        x, y = msg.x, msg.y
        if msg.get_type() == "MISSION_ITEM":
            x, y = round(x * 1e7), round(y * 1e7)
        fields = {k: getattr(msg, k) for k in cls.__dataclass_fields__ if k not in ("x", "y")}
        return cls(**{**fields, "x": int(x), "y": int(y)})

    def as_dict(self) -> dict[str, float | int]:
        return asdict(self)

    def acceptance_m(self, default_m: float) -> float:
        """A waypoint's acceptance radius (param2, m), or ``default_m`` when it gives none."""
        return self.param2 if self.param2 > 0 else default_m


def not_carried_note(items: Sequence[MissionItem]) -> str | None:
    """What to tell the operator of a stored mission whose items aim or set up what the
    vehicle does not carry (STATUSTEXT's 50 bytes); None when it has none."""
    count = sum(1 for item in items if item.command in NOT_CARRIED)
    if not count:
        return None
    return f"Mission: {count} gimbal/video/yaw item{'s' * (count > 1)} ignored"


def delay_loiter(item: MissionItem, alt_msl: float) -> MissionItem:
    """A NAV_DELAY as the executor flies it, as PX4 and ArduPlane hold a plane: a LOITER_TIME
    of its seconds round the last point flown to (it has no place of its own), at that
    point's height ``alt_msl``, on the default radius, clockwise."""
    return replace(item, command=d.MAV_CMD_NAV_LOITER_TIME, frame=d.MAV_FRAME_GLOBAL,
                   param2=0.0, param3=0.0, param4=0.0, x=0, y=0, z=alt_msl)  # fmt: skip


def change_speed(item: MissionItem, speed: float) -> float:
    """The speed flown after a DO_CHANGE_SPEED item (NaN: the default): param2 m/s for an
    airspeed or a ground speed (param1 0 or 1, both flown as the airspeed, as PX4 does),
    the default again for -2 or 0; -1, and climb or descent speeds (2, 3), change nothing."""
    if item.param1 not in (0.0, 1.0) or item.param2 == -1:
        return speed
    return item.param2 if item.param2 > 0 else math.nan


def check_params(item: MissionItem) -> int:
    """INVALID_PARAMn for a parameter that is infinite, huge, or NaN where a number is read."""
    needed = NEEDS_NUMBER.get(item.command, ())
    values = (item.param1, item.param2, item.param3, item.param4)
    for n, value in enumerate(values, start=1):
        if math.isnan(value):
            if n in needed:
                return INVALID_PARAM[n - 1]
        elif not abs(value) <= MAX_PARAM:
            return INVALID_PARAM[n - 1]
    return d.MAV_MISSION_ACCEPTED


def check_item(item: MissionItem, count: int) -> int:
    """MAV_MISSION_ACCEPTED, or the MAV_MISSION_RESULT that says why the item is refused."""
    if item.command not in SUPPORTED.get(item.mission_type, frozenset()):
        return d.MAV_MISSION_UNSUPPORTED
    params = check_params(item)
    if params != d.MAV_MISSION_ACCEPTED:
        return params
    if item.command == d.MAV_CMD_DO_SET_SERVO:
        return _servo_refusal(item)
    if item.command in CAMERA_ITEMS:
        return _camera_refusal(item)
    if item.command == d.MAV_CMD_DO_GRIPPER and item.param2 not in (0.0, 1.0):  # release, grab
        return d.MAV_MISSION_INVALID_PARAM2
    if item.command == d.MAV_CMD_DO_SET_ACTUATOR:
        return _actuator_refusal(item)
    if item.command == d.MAV_CMD_DO_JUMP:
        target = round(item.param1)
        if not 0 <= target < count or target == item.seq:
            return d.MAV_MISSION_INVALID_PARAM1
        return d.MAV_MISSION_ACCEPTED
    if item.command == d.MAV_CMD_NAV_DELAY and item.param1 < 0:  # until a time of day
        return d.MAV_MISSION_INVALID_PARAM1
    if item.command == d.MAV_CMD_DO_SET_HOME:  # 1: the aircraft's place; 0: the item's
        if item.param1 not in (0.0, 1.0):
            return d.MAV_MISSION_INVALID_PARAM1
        if item.param1 == 1.0:
            return d.MAV_MISSION_ACCEPTED
    if item.command in POSITIONLESS:
        return d.MAV_MISSION_ACCEPTED
    if item.frame not in GLOBAL_FRAMES:
        return d.MAV_MISSION_UNSUPPORTED_FRAME
    if not -900_000_000 <= item.x <= 900_000_000:
        return d.MAV_MISSION_INVALID_PARAM5_X
    if not -1_800_000_000 <= item.y <= 1_800_000_000:
        return d.MAV_MISSION_INVALID_PARAM6_Y
    if item.x == 0 and item.y == 0 and item.command != d.MAV_CMD_NAV_TAKEOFF:
        return d.MAV_MISSION_INVALID_PARAM5_X
    if not abs(item.z) <= MAX_ALT_M:  # NaN fails too: every positional item needs a height
        return d.MAV_MISSION_INVALID_PARAM7
    return d.MAV_MISSION_ACCEPTED


def _servo_refusal(item: MissionItem) -> int:
    """A DO_SET_SERVO's output must be one of the card's, its pulse one the card puts out."""
    if item.param1 != round(item.param1) or round(item.param1) not in SERVO_OUTPUTS:
        return d.MAV_MISSION_INVALID_PARAM1
    low, high = SERVO_PULSES_US
    if item.param2 != round(item.param2) or not low <= item.param2 <= high:
        return d.MAV_MISSION_INVALID_PARAM2
    return d.MAV_MISSION_ACCEPTED


INT32_SENTINELS = (2**31 - 1, -(2**31))  # an integer field's "not given"


def actuator_values(item: MissionItem) -> tuple[float, ...]:
    """A DO_SET_ACTUATOR item's values for actuator sets 1-6 (NaN: leave that set). Sets 5
    and 6 ride in x and y, scaled by 1e7 as QGroundControl 4.4 scales every item's."""
    fifth, sixth = (math.nan if v in INT32_SENTINELS else v / 1e7 for v in (item.x, item.y))
    return (item.param1, item.param2, item.param3, item.param4, fifth, sixth)


def _actuator_refusal(item: MissionItem) -> int:
    """Each set's value within -1..1 or NaN; the index (param7) 0, the only one there is."""
    for n, value in enumerate(actuator_values(item)):
        if not (math.isnan(value) or -1.0 <= value <= 1.0):
            return INVALID_PARAM[n]
    if item.z != 0.0:
        return d.MAV_MISSION_INVALID_PARAM7
    return d.MAV_MISSION_ACCEPTED


def _camera_refusal(item: MissionItem) -> int:
    """A distance, an interval or a count of photos is not negative."""
    if item.command == d.MAV_CMD_DO_SET_CAM_TRIGG_DIST and item.param1 < 0:
        return d.MAV_MISSION_INVALID_PARAM1
    if item.command == d.MAV_CMD_IMAGE_START_CAPTURE:
        if item.param2 < 0:
            return d.MAV_MISSION_INVALID_PARAM2
        if item.param3 < 0 or item.param3 != round(item.param3):
            return d.MAV_MISSION_INVALID_PARAM3
    return d.MAV_MISSION_ACCEPTED


def check_mission(items: list[MissionItem]) -> int:
    """The first refusal in a whole mission, or MAV_MISSION_ACCEPTED."""
    return first_refusal(items)[0]


# A take-off after an item the aircraft flies to (as PX4 refuses it): from the runway the
# mission would fly that item first, and an ArduPilot .waypoints file's line 0 (home, at
# ground level, sent as item 0 by MAVProxy's `wp load`) is such an item.
TAKEOFF_NOT_FIRST = d.MAV_MISSION_ERROR


def first_refusal(items: list[MissionItem]) -> tuple[int, MissionItem | None]:
    """The first refused item of a mission and why (MAV_MISSION_ACCEPTED, None: none)."""
    flown_before = False
    for item in items:
        result = check_item(item, len(items))
        if result != d.MAV_MISSION_ACCEPTED:
            return result, item
        if item.mission_type != d.MAV_MISSION_TYPE_MISSION:
            continue
        if item.command == d.MAV_CMD_NAV_TAKEOFF and flown_before:
            return TAKEOFF_NOT_FIRST, item
        flown_before |= item.command in NAV_COMMANDS
    return d.MAV_MISSION_ACCEPTED, None


def jump_target(item: MissionItem, index: int, jumps_done: dict[int, int], count: int) -> int:
    """Where the DO_JUMP at ``index`` of ``count`` items sends the mission, its count in
    ``jumps_done`` (by seq) taken: its target while repeats remain (for ever when param2 is
    negative), else the next item."""
    repeats, done = round(item.param2), jumps_done.get(item.seq, 0)
    if 0 <= repeats <= done:
        return index + 1
    if repeats >= 0:  # an endless jump keeps no count (the executor's loop check needs that)
        jumps_done[item.seq] = done + 1
    return max(0, min(round(item.param1), count))


def next_flown(
    items: Sequence[MissionItem], seq: int, jumps_done: Mapping[int, int]
) -> MissionItem | None:
    """The item flown from ``seq`` on (speed changes, markers and jumps followed as they
    will be, given the jumps done so far), or None."""
    jumps = dict(jumps_done)
    for _ in range(MAX_JUMPS_PER_STEP):
        if seq >= len(items):
            return None
        item = items[seq]
        if item.command == d.MAV_CMD_DO_JUMP:
            seq = jump_target(item, seq, jumps, len(items))
        elif item.command in PASSED_OVER:
            seq += 1
        else:
            return item
    return None
