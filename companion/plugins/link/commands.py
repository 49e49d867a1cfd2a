"""The commands the link answers itself or hands to the vehicle over the bus."""

from __future__ import annotations

from typing import TYPE_CHECKING

from companion.mavlink.codec import dialect as d
from companion.mavlink.command_service import CommandArgs, Outcome
from companion.mavlink.telemetry import STREAMS
from companion.messages import CommandId

if TYPE_CHECKING:
    from companion.plugins.link.mavlink_link import MavlinkLink

BUS_ACK_TIMEOUT_S = 3.0


def register_commands(link: MavlinkLink) -> None:
    """Wire each supported MAV_CMD to its handler."""
    service = link.commands

    def arm_disarm(args: CommandArgs) -> Outcome:
        command = CommandId.START if args.params[0] >= 0.5 else CommandId.STOP
        return Outcome(defer_seq=link.publish_command(command), timeout_s=BUS_ACK_TIMEOUT_S)

    def reboot(args: CommandArgs) -> Outcome:
        if round(args.params[0]) != 1:  # only "reboot the autopilot" is meaningful here
            return Outcome(d.MAV_RESULT_UNSUPPORTED)
        return Outcome(defer_seq=link.publish_command(CommandId.RESTART_PLUGINS))

    def request_message(args: CommandArgs) -> Outcome:
        msg_id = round(args.params[0])
        if msg_id == d.MAVLINK_MSG_ID_AUTOPILOT_VERSION:
            return Outcome(extra=[link.identity.autopilot_version()])
        if msg_id == d.MAVLINK_MSG_ID_PROTOCOL_VERSION:
            return Outcome(extra=[link.identity.protocol_version()])
        if msg_id in STREAMS:
            msg = STREAMS[msg_id].build(link.mav, link.snapshot)
            if msg is None:
                return Outcome(d.MAV_RESULT_TEMPORARILY_REJECTED)
            return Outcome(extra=[msg])
        return Outcome(d.MAV_RESULT_UNSUPPORTED)

    def capabilities(args: CommandArgs) -> Outcome:
        return Outcome(extra=[link.identity.autopilot_version()])

    def set_interval(args: CommandArgs) -> Outcome:
        schedule = link.router.schedules[args.peer.endpoint]
        ok = schedule.set_interval(round(args.params[0]), args.params[1])
        return Outcome(d.MAV_RESULT_ACCEPTED if ok else d.MAV_RESULT_UNSUPPORTED)

    def get_interval(args: CommandArgs) -> Outcome:
        msg_id = round(args.params[0])
        interval = link.router.schedules[args.peer.endpoint].interval_us(msg_id)
        return Outcome(extra=[link.mav.message_interval_encode(msg_id, interval)])

    service.register(d.MAV_CMD_COMPONENT_ARM_DISARM, arm_disarm)
    service.register(d.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN, reboot)
    service.register(d.MAV_CMD_REQUEST_MESSAGE, request_message)
    service.register(d.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES, capabilities)
    service.register(d.MAV_CMD_SET_MESSAGE_INTERVAL, set_interval)
    service.register(d.MAV_CMD_GET_MESSAGE_INTERVAL, get_interval)
