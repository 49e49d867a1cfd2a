"""Requests for messages and their rates: the link answers these itself."""

from __future__ import annotations

from companion.link.codec import dialect as d
from companion.link.command_rules import whole_or
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands.port import VehiclePort
from companion.link.identity import IdentityService
from companion.link.link_router import LinkRouter
from companion.link.metadata_service import MetadataService
from companion.link.mode_messages import available_modes
from companion.link.telemetry import STREAMS

METADATA_MESSAGES = (d.MAVLINK_MSG_ID_COMPONENT_METADATA, d.MAVLINK_MSG_ID_COMPONENT_INFORMATION)


class MessageRequests:
    """REQUEST_MESSAGE, REQUEST_AUTOPILOT_CAPABILITIES, SET_ and GET_MESSAGE_INTERVAL, and
    the older one-message requests GET_HOME_POSITION and REQUEST_PROTOCOL_VERSION."""

    def __init__(
        self,
        port: VehiclePort,
        identity: IdentityService,
        router: LinkRouter,
        metadata: MetadataService | None = None,
    ) -> None:
        self.port = port
        self.identity = identity
        self.router = router
        self.mav = router.mav
        self.metadata = metadata  # None: no component information (UNSUPPORTED at once)

    def register(self, service: CommandService) -> None:
        service.register(d.MAV_CMD_REQUEST_MESSAGE, self.request_message)
        service.register(d.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES, self.capabilities)
        service.register(d.MAV_CMD_SET_MESSAGE_INTERVAL, self.set_interval)
        service.register(d.MAV_CMD_GET_MESSAGE_INTERVAL, self.get_interval)
        service.register(d.MAV_CMD_GET_HOME_POSITION, self.home_position)
        service.register(d.MAV_CMD_REQUEST_PROTOCOL_VERSION, self.protocol_version)

    def request_message(self, args: CommandArgs) -> Outcome:
        msg_id = round(args.params[0])
        if msg_id == d.MAVLINK_MSG_ID_AUTOPILOT_VERSION:
            return Outcome(extra=[self.identity.autopilot_version()])
        if msg_id == d.MAVLINK_MSG_ID_PROTOCOL_VERSION:
            return Outcome(extra=[self.identity.protocol_version()])
        if msg_id == d.MAVLINK_MSG_ID_AVAILABLE_MODES:
            px4 = self.identity.autopilot == d.MAV_AUTOPILOT_PX4
            modes = available_modes(self.mav, whole_or(args.params[1], 0), px4)
            return Outcome(extra=modes) if modes else Outcome(d.MAV_RESULT_DENIED)
        if self.metadata is not None and msg_id in METADATA_MESSAGES:
            time_boot_ms = self.port.snapshot.time_boot_ms
            if msg_id == d.MAVLINK_MSG_ID_COMPONENT_METADATA:
                return Outcome(extra=[self.metadata.component_metadata(time_boot_ms)])
            return Outcome(extra=[self.metadata.component_information(time_boot_ms)])
        if msg_id in STREAMS:
            msg = STREAMS[msg_id].build(self.mav, self.port.snapshot)
            if msg is None:
                return Outcome(d.MAV_RESULT_TEMPORARILY_REJECTED)
            return Outcome(extra=[msg])
        return Outcome(d.MAV_RESULT_UNSUPPORTED)

    def home_position(self, args: CommandArgs) -> Outcome:
        """As REQUEST_MESSAGE for HOME_POSITION (deprecated for it, still sent by MAVProxy
        and older scripts): the ack, then the message; TEMPORARILY_REJECTED before a home."""
        msg = STREAMS[d.MAVLINK_MSG_ID_HOME_POSITION].build(self.mav, self.port.snapshot)
        if msg is None:
            return Outcome(d.MAV_RESULT_TEMPORARILY_REJECTED)
        return Outcome(extra=[msg])

    def protocol_version(self, args: CommandArgs) -> Outcome:
        """As REQUEST_MESSAGE for PROTOCOL_VERSION: MAVLink 2 spoken."""
        return Outcome(extra=[self.identity.protocol_version()])

    def capabilities(self, args: CommandArgs) -> Outcome:
        return Outcome(extra=[self.identity.autopilot_version()])

    def set_interval(self, args: CommandArgs) -> Outcome:
        """Accepted for every message the vehicle streams, at the rate it can serve (said
        in a MESSAGE_INTERVAL after the ack); UNSUPPORTED only for one it cannot send."""
        msg_id = round(args.params[0])
        schedule = self.router.schedules[args.peer.endpoint]
        if not schedule.set_interval(msg_id, args.params[1]):
            return Outcome(d.MAV_RESULT_UNSUPPORTED)
        served = self.mav.message_interval_encode(msg_id, schedule.interval_us(msg_id))
        return Outcome(extra=[served])

    def get_interval(self, args: CommandArgs) -> Outcome:
        msg_id = round(args.params[0])
        interval = self.router.schedules[args.peer.endpoint].interval_us(msg_id)
        return Outcome(extra=[self.mav.message_interval_encode(msg_id, interval)])
