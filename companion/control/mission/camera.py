"""A camera's shutter on a servo output: when to take a photo, as ArduPilot's servo camera
(``CAM1_TYPE`` 1) and PX4's camera trigger take them.

What QGroundControl puts in a survey or a waypoint's camera section sets it going:
DO_SET_CAM_TRIGG_DIST (a photo every param1 metres flown over the ground, 0 stops; param3
1: one at once too), IMAGE_START_CAPTURE (a photo every param2 seconds, param3 of them, 0:
no end; param2 0 and param3 1: one photo), IMAGE_STOP_CAPTURE (stops either), and
DO_DIGICAM_CONTROL (param5 1: one photo). Each photo holds the output at ``CAM1_SERVO_ON``
for ``CAM1_DURATION``, then at ``CAM1_SERVO_OFF``; photos come at most one every
``CAM1_INTRVAL_MIN`` and never while the shutter is still held, so one due then waits.

Pure: items and positions in, photos and pulses out; the controller's plug-in drives the
output and tells the log and the ground station of each photo.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from companion.control.mission.items import CAMERA_ITEMS, MissionItem
from companion.params import ParamDecl, declared_values
from mavlink_dialect import companion as d

TYPE_PARAM = "CAM1_TYPE"
NO_CAMERA, SERVO_CAMERA = 0.0, 1.0
CAMERA_PARAMS = (
    ParamDecl(TYPE_PARAM, NO_CAMERA, values=((NO_CAMERA, "None"), (SERVO_CAMERA, "Servo")),
              doc="How the camera's shutter is worked: None (camera items do nothing) or "
                  "Servo (a pulse on CAM1_OUTPUT)"),
    ParamDecl("CAM1_OUTPUT", 7.0, 1.0, 8.0, "",
              "The servo card output the shutter is wired to, numbered from 1 as "
              "DO_SET_SERVO numbers them (ArduPilot: the output whose SERVOn_FUNCTION is 10)"),
    ParamDecl("CAM1_SERVO_ON", 1300.0, 1000.0, 2000.0, "us",
              "The pulse that presses the shutter"),
    ParamDecl("CAM1_SERVO_OFF", 1100.0, 1000.0, 2000.0, "us",
              "The pulse that releases the shutter, held between photos"),
    ParamDecl("CAM1_DURATION", 0.1, 0.0, 5.0, "s", "How long the shutter is held pressed"),
    ParamDecl("CAM1_INTRVAL_MIN", 0.0, 0.0, 10.0, "s",
              "The shortest time between photos the camera can take; a photo due sooner "
              "waits"),
)  # fmt: skip
Point = tuple[float, float]  # metres north and east of home


def asks_for_photos(item: MissionItem) -> bool:
    """Whether a camera item would take photos (a stop, or a distance of 0, takes none)."""
    if item.command == d.MAV_CMD_DO_SET_CAM_TRIGG_DIST:
        return item.param1 > 0
    if item.command == d.MAV_CMD_IMAGE_START_CAPTURE:
        return item.param2 > 0 or round(item.param3) == 1
    return item.command == d.MAV_CMD_DO_DIGICAM_CONTROL and item.x == 1


@dataclass(frozen=True)
class CameraConfig:
    """The camera's parameters, grouped."""

    servo: bool = False  # CAM1_TYPE is Servo
    output: int = 7
    on_us: int = 1300
    off_us: int = 1100
    duration_s: float = 0.1
    min_interval_s: float = 0.0

    @classmethod
    def from_params(cls, values: Mapping[str, float]) -> CameraConfig:
        v = declared_values(CAMERA_PARAMS, values)
        return cls(
            v[TYPE_PARAM] == SERVO_CAMERA, round(v["CAM1_OUTPUT"]), round(v["CAM1_SERVO_ON"]),
            round(v["CAM1_SERVO_OFF"]), v["CAM1_DURATION"], v["CAM1_INTRVAL_MIN"],
        )  # fmt: skip


@dataclass
class CameraStep:
    """What one control step asks of the camera's output."""

    photo: bool = False  # a photo was taken (its number is ``CameraTrigger.seq``, from 0)
    pulses: list[tuple[int, int]] = field(default_factory=list)  # (output, µs) to set now


@dataclass
class CameraTrigger:
    """When photos are due, from the camera items passed and the positions flown."""

    config: CameraConfig = field(default_factory=CameraConfig)
    taken: int = 0  # photos taken so far
    distance_m: float = 0.0  # a photo every this many metres (0: not by distance)
    interval_s: float = 0.0  # a photo every this many seconds (0: not by time)
    left: int = 0  # photos still to take by time (0: no end)

    def __post_init__(self) -> None:
        self._wanted = False  # one photo asked for at once (or due and waiting)
        self._last_at: Point | None = None  # where the last photo (or the count) started
        self._last_s = -math.inf  # when the last photo was taken
        self._release_s: float | None = None  # when the held shutter is let go

    @property
    def seq(self) -> int:
        """The last photo's number: the first is 0, as PX4's camera trigger numbers them,
        and QGroundControl's GeoTag Images tags the image of that index (by name) with it."""
        return self.taken - 1

    @property
    def busy(self) -> bool:
        """Whether a photo may fall due or the shutter is held (else ``step`` does nothing)."""
        return bool(
            self._wanted or self.distance_m or self.interval_s or self._release_s is not None
        )

    def apply_item(self, item: MissionItem) -> None:
        """A mission's camera item (param5 is the item's x: a count, not a latitude)."""
        if item.command in CAMERA_ITEMS:
            params = (item.param1, item.param2, item.param3, item.param4, float(item.x))
            self.apply(item.command, params)

    def apply(self, command: int, params: tuple[float, ...]) -> None:
        """A camera item (or command) with its parameters param1..param7."""
        p = (*params, *(0.0,) * 7)[:7]
        if command == d.MAV_CMD_DO_SET_CAM_TRIGG_DIST:
            self.distance_m = max(p[0], 0.0)
            self._last_at = None  # counted from where the aircraft is when it is set
            self._wanted |= p[2] == 1 and self.distance_m > 0
        elif command == d.MAV_CMD_IMAGE_START_CAPTURE:
            interval, count = max(p[1], 0.0), max(round(p[2]), 0)
            if interval > 0:
                self.interval_s, self.left = interval, count
            self._wanted |= interval > 0 or count == 1  # the first at once, as PX4 takes it
        elif command == d.MAV_CMD_IMAGE_STOP_CAPTURE:
            self.distance_m = self.interval_s = 0.0
            self.left, self._wanted = 0, False
        elif command == d.MAV_CMD_DO_DIGICAM_CONTROL:
            self._wanted |= p[4] == 1

    def step(self, t_s: float, pos: Point) -> CameraStep:
        """This control step's photo and pulses, at time ``t_s`` and position ``pos``."""
        out = CameraStep()
        cfg = self.config
        if self._release_s is not None and t_s >= self._release_s:
            out.pulses.append((cfg.output, cfg.off_us))
            self._release_s = None
        if not self._due(t_s, pos):
            return out
        if self._release_s is not None or t_s - self._last_s < cfg.min_interval_s:
            self._wanted = True  # taken when the shutter is free again
            return out
        self._wanted = False
        self.taken += 1
        self._last_s, self._last_at = t_s, pos
        if self.interval_s > 0 and self.left > 0:
            self.left -= 1
            if self.left == 0:
                self.interval_s = 0.0
        out.photo = True
        out.pulses.append((cfg.output, cfg.on_us))
        self._release_s = t_s + cfg.duration_s
        return out

    def _due(self, t_s: float, pos: Point) -> bool:
        if self._wanted:
            return True
        if self.distance_m > 0:
            if self._last_at is None:
                self._last_at = pos
                return False
            flown = math.hypot(pos[0] - self._last_at[0], pos[1] - self._last_at[1])
            if flown >= self.distance_m:
                return True
        return self.interval_s > 0 and t_s - self._last_s >= self.interval_s
