"""A camera on a servo output, from a ground station as from a mission: QGroundControl's
photo button (its simple camera control sends DO_DIGICAM_CONTROL, param5 1),
DO_SET_CAM_TRIGG_DIST, IMAGE_START_CAPTURE and IMAGE_STOP_CAPTURE
(``companion.control.mission.camera`` says what each does).

The flight controller works the camera and answers; it runs only while the vehicle is
armed (its group is ``flight``), so the commands are refused at once before then, with
the reason, as DO_SET_SERVO is. A camera not set up (``CAM1_TYPE`` None) or wired to a
surface's output is refused by the controller, with the reason.
"""

from __future__ import annotations

import math

from companion.link.codec import dialect as d
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands.port import BUS_ACK_TIMEOUT_S, VehiclePort, plugin_running, refuse
from companion.messages import CommandId

CONTROLLER = b"control.fixed_wing"  # the plug-in that answers


class CameraCommands:
    """The camera's commands, handed to the flight controller."""

    def __init__(self, port: VehiclePort) -> None:
        self.port = port
        self.service: CommandService | None = None

    def register(self, service: CommandService) -> None:
        self.service = service
        # One line each: the reference page (docs/gen_reference_commands.py) reads them.
        service.register(d.MAV_CMD_DO_DIGICAM_CONTROL, self.camera)
        service.register(d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, self.camera)
        service.register(d.MAV_CMD_IMAGE_START_CAPTURE, self.camera)
        service.register(d.MAV_CMD_IMAGE_STOP_CAPTURE, self.camera)

    def camera(self, args: CommandArgs) -> Outcome:
        """A photo, a distance or an interval between photos, or none, for the camera on a
        servo output (the flight controller answers); DENIED while disarmed."""
        if not plugin_running(self.port, CONTROLLER):
            return refuse(self.port, self.service, "Camera: photos only while armed")
        p = [0.0 if math.isnan(v) else v for v in args.params]
        params = (args.command, p[0], p[1], p[2], p[4])
        seq = self.port.publish_command(CommandId.CAMERA, params, to=CONTROLLER)
        return Outcome(defer_seq=seq, timeout_s=BUS_ACK_TIMEOUT_S)
