"""The controller plug-in's camera: a mission's camera items worked on the shutter's servo
output, each photo told to the flight log and the ground station.

The plug-in hands in how to publish: the shutter's pulses go to the servo output as
DO_SET_SERVO commands (on ``link/commands``, as a mission's DO_SET_SERVO does), each photo
as a CameraCapture (``camera/capture``). With ``CAM1_TYPE`` None, or the output one a
surface uses, camera items take no photo and the operator is told once why.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from companion.control.mission.camera import CameraConfig, CameraTrigger, asks_for_photos
from companion.control.mission.items import MissionItem
from companion.messages import (
    CAMERA_SEQ,
    CameraCapture,
    GpsFix,
    NavState,
    VehicleCommand,
)
from mavlink_dialect import companion as d

log = logging.getLogger("companion.camera")


@dataclass(frozen=True)
class CameraPorts:
    """What the camera publishes through and reads, from its plug-in."""

    capture: Callable[[CameraCapture], None]  # a photo taken
    command: Callable[[VehicleCommand], None]  # a pulse for the servo output
    say: Callable[[int, int, str], None]  # (t_us, MAV_SEVERITY, text) for the operator
    gps: Callable[[], GpsFix | None]  # the newest fix (its UTC stamps the photos)
    home_alt: Callable[[], float]  # home's altitude above sea level


class CameraShots:
    """Camera items in, shutter pulses and photos out."""

    def __init__(self, ports: CameraPorts, surface_outputs: Mapping[int, str]) -> None:
        self.trigger = CameraTrigger()
        self.ports = ports
        self.surface_outputs = surface_outputs
        self._told = False  # why photos cannot be taken was said (once a configuration)

    def configure(self, values: Mapping[str, float]) -> None:
        """The CAM1_* parameters' values (at start and on every change)."""
        self.trigger.config = CameraConfig.from_params(values)
        self._told = False

    def outputs(self) -> dict[int, str]:
        """The output its shutter pulses go to, for a servo-triggered camera."""
        config = self.trigger.config
        return {config.output: "camera"} if config.servo else {}

    def step(self, nav: NavState, items: list[MissionItem], pos: tuple[float, float]) -> None:
        """This control step: the items the mission passed, the photo due, its pulses."""
        # Told only when photos were asked for: a landing pattern's camera stop asks none.
        asked = any(asks_for_photos(i) for i in items)
        problem = self._problem() if asked or self.trigger.distance_m else None
        if problem is not None:
            if not self._told:
                self.ports.say(nav.t_us, d.MAV_SEVERITY_WARNING, problem)
                self._told = True
            return
        for item in items:
            self.trigger.apply_item(item)
        shot = self.trigger.step(nav.t_us / 1e6, pos)
        for output, pulse in shot.pulses:
            self.ports.command(VehicleCommand.set_servo(nav.t_us, CAMERA_SEQ, output, pulse))
        if shot.photo:
            self.ports.capture(self._capture(nav))
            log.info("photo %d at %.7f, %.7f", self.trigger.seq, nav.lat_deg, nav.lon_deg)

    def command(self, command: int, params: tuple[float, ...]) -> str | None:
        """A ground station's camera command (param1, 2, 3 and 5 of it) taken: None, or
        why it is refused (no camera set up, or one on a surface's output)."""
        problem = self._problem()
        if problem is None:
            self.trigger.apply(command, (params[0], params[1], params[2], 0.0, params[3]))
        return problem

    def _problem(self) -> str | None:
        """Why no photo can be taken (a text for the operator), or None."""
        config = self.trigger.config
        if not config.servo:
            return "Camera: CAM1_TYPE is None: no photos"
        surface = self.surface_outputs.get(config.output)
        if surface is not None:
            return f"Camera: output {config.output} drives the {surface}"
        return None

    def _capture(self, nav: NavState) -> CameraCapture:
        msg = CameraCapture(t_us=nav.t_us, seq=self.trigger.seq, result=1)
        fix = self.ports.gps()
        if fix is not None and fix.utc_us > 0:
            msg.timestamp_utc = fix.utc_us + (nav.t_us - fix.t_us)
        msg.lat, msg.lon, msg.alt = nav.lat_deg, nav.lon_deg, nav.alt_msl_m
        msg.ground_distance = nav.alt_msl_m - self.ports.home_alt()
        msg.q[:] = list(nav.q)
        return msg
