"""Arming, disarming, rebooting and failure injection: commands for the whole vehicle."""

from __future__ import annotations

from companion.control.prearm import FORCE_ARM, PREFIX
from companion.link.codec import dialect as d
from companion.link.command_rules import whole_or
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands.port import BUS_ACK_TIMEOUT_S, VehiclePort
from companion.messages import CommandId

FORCE_DISARM = FORCE_ARM  # param2 of COMPONENT_ARM_DISARM that means "even in the air"
MAX_PREARM_TEXTS = 3
ALERT = d.MAV_SEVERITY_EMERGENCY  # QGroundControl shows it over the map and speaks it


class ArmingCommands:
    """MAV_CMD_COMPONENT_ARM_DISARM, PREFLIGHT_REBOOT_SHUTDOWN and INJECT_FAILURE."""

    def __init__(self, port: VehiclePort) -> None:
        self.port = port

    def register(self, service: CommandService) -> None:
        service.register(d.MAV_CMD_COMPONENT_ARM_DISARM, self.arm_disarm)
        service.register(d.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN, self.reboot)
        service.register(d.MAV_CMD_INJECT_FAILURE, self.inject_failure)

    def arm_disarm(self, args: CommandArgs) -> Outcome:
        command = CommandId.START if args.params[0] >= 0.5 else CommandId.STOP
        control = self.port.snapshot.control
        in_air = control is not None and not control.landed
        if command == CommandId.STOP and in_air and whole_or(args.params[1], 0) != FORCE_DISARM:
            # As ArduPilot and PX4: stopping the flight plug-ins in the air drops the
            # aircraft, so it takes the magic number to mean it.
            self.port.statustext("Disarm refused: flying (param2 21196 forces it)")
            return Outcome(d.MAV_RESULT_DENIED)
        if command == CommandId.STOP and in_air:  # the operator must hear that it falls
            self.port.statustext("Disarmed in flight (forced): motor and surfaces off", ALERT)
        forced = whole_or(args.params[1], 0) == FORCE_ARM
        checked = (
            command == CommandId.START and not forced and self.port.param("ARMING_CHECK") >= 0.5
        )
        if checked and (found := self.port.prearm_failures()):
            for reason in found[:MAX_PREARM_TEXTS]:  # as ArduPilot: one line per reason
                self.port.statustext(PREFIX + reason, d.MAV_SEVERITY_CRITICAL)
            return Outcome(d.MAV_RESULT_DENIED)
        # The supervisor checks the flight plug-ins' devices when param[1] asks it to.
        params = (1.0, 1.0 if checked else 0.0) if command == CommandId.START else ()
        seq = self.port.publish_command(command, params)
        return Outcome(defer_seq=seq, timeout_s=BUS_ACK_TIMEOUT_S)

    def reboot(self, args: CommandArgs) -> Outcome:
        if round(args.params[0]) != 1:  # only "reboot the autopilot" is meaningful here
            return Outcome(d.MAV_RESULT_UNSUPPORTED)
        # Acknowledged now, as ArduPilot and PX4 do before they reboot: the restart takes
        # this link down too, so an answer deferred to the bus would never go out.
        self.port.statustext("Rebooting: restarting every plug-in", d.MAV_SEVERITY_NOTICE)
        self.port.publish_command(CommandId.RESTART_PLUGINS)
        return Outcome(d.MAV_RESULT_ACCEPTED)

    def inject_failure(self, args: CommandArgs) -> Outcome:
        """As PX4: off unless SYS_FAILURE_EN is 1; the simulator bridge applies it to its
        emulated devices and answers (UNSUPPORTED for what it cannot)."""
        if self.port.param("SYS_FAILURE_EN") < 0.5:
            self.port.statustext("Failure injection is off (set SYS_FAILURE_EN to 1)")
            return Outcome(d.MAV_RESULT_DENIED)
        if not self.port.simulated:
            self.port.statustext("Failure injection needs the simulator")
            return Outcome(d.MAV_RESULT_UNSUPPORTED)
        unit, kind, instance = args.params[:3]
        params = (float(round(unit)), float(round(kind)), float(whole_or(instance, 0)))
        seq = self.port.publish_command(CommandId.INJECT_FAILURE, params)
        return Outcome(defer_seq=seq, timeout_s=BUS_ACK_TIMEOUT_S)
