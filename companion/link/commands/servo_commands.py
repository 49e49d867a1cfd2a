"""MAV_CMD_DO_SET_SERVO: one of the servo card's spare outputs to a pulse, as ArduPilot
sets a payload release, a camera trigger or a light (MAVProxy's ``servo set N PWM``).

param1 the output, numbered from 1 as ArduPilot's SERVOn (1 is the Mini SSC's servo 0),
param2 the pulse in µs within what the card puts out (1000-2000: its 90° range); the
command rules refuse anything else. The servo output plug-in answers: an output that
drives a surface of the airframe is refused with the reason, as ArduPilot refuses an output
with a function. It runs only while the vehicle is armed (its group is ``flight``): the
command is refused at once before then, with the reason.

MAV_CMD_DO_GRIPPER (MAVSDK's Gripper plug-in): param2 0 releases, 1 grabs, the gripper on
the output ``GRIP_OUTPUT`` (``companion.control.mission.gripper``). The flight controller
works it and answers, as it does the camera; refused at once while disarmed too.

MAV_CMD_DO_SET_ACTUATOR (MAVSDK's ``Action.set_actuator``, PX4's generic actuator control):
param1-6 actuator sets 1-6 from -1 to 1 (NaN: leave), param7 the index, 0. The flight
controller sets the outputs ``ACT_SETn_OUT`` wire them to and answers
(``companion.control.mission.actuator_sets``); refused at once while disarmed.
"""

from __future__ import annotations

import math

from companion.link.codec import dialect as d
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands.port import BUS_ACK_TIMEOUT_S, VehiclePort, plugin_running, refuse
from companion.messages import CommandId

SERVO_OUTPUT = b"actuators.minissc"  # the plug-in that answers DO_SET_SERVO
CONTROLLER = b"control.fixed_wing"  # and DO_GRIPPER


class ServoCommands:
    """DO_SET_SERVO, DO_GRIPPER and DO_SET_ACTUATOR."""

    def __init__(self, port: VehiclePort) -> None:
        self.port = port
        self.service: CommandService | None = None

    def register(self, service: CommandService) -> None:
        self.service = service
        # One line each: the reference page (docs/gen_reference_commands.py) reads them.
        service.register(d.MAV_CMD_DO_SET_SERVO, self.set_servo)
        service.register(d.MAV_CMD_DO_GRIPPER, self.gripper)
        service.register(d.MAV_CMD_DO_SET_ACTUATOR, self.set_actuator)

    def set_servo(self, args: CommandArgs) -> Outcome:
        """A spare output of the servo card to the pulse, answered by the servo output (an
        output a surface uses DENIED); DENIED at once while disarmed."""
        if not plugin_running(self.port, SERVO_OUTPUT):
            text = "Set servo: the servo output runs only while armed"
            return refuse(self.port, self.service, text)
        output, pulse = (round(p) for p in args.params[:2])
        seq = self.port.publish_command(CommandId.SET_SERVO, (output, pulse), to=SERVO_OUTPUT)
        return Outcome(defer_seq=seq, timeout_s=BUS_ACK_TIMEOUT_S)

    def gripper(self, args: CommandArgs) -> Outcome:
        """Grab or release the payload, answered by the flight controller (a gripper not
        set up DENIED, with the reason); DENIED at once while disarmed."""
        if not plugin_running(self.port, CONTROLLER):
            return refuse(self.port, self.service, "Gripper: works only while armed")
        action = (round(args.params[1]),)
        seq = self.port.publish_command(CommandId.GRIPPER, action, to=CONTROLLER)
        return Outcome(defer_seq=seq, timeout_s=BUS_ACK_TIMEOUT_S)

    def set_actuator(self, args: CommandArgs) -> Outcome:
        """Actuator sets 1-6 to their values, answered by the flight controller (no set
        wired, or one on a surface's output, DENIED with the reason); DENIED at once while
        disarmed."""
        if not plugin_running(self.port, CONTROLLER):
            return refuse(self.port, self.service, "Set actuator: works only while armed")
        index = 0.0 if math.isnan(args.params[6]) else args.params[6]
        params = (*args.params[:6], index)
        seq = self.port.publish_command(CommandId.SET_ACTUATOR, params, to=CONTROLLER)
        return Outcome(defer_seq=seq, timeout_s=BUS_ACK_TIMEOUT_S)
