"""The commands the link answers itself or hands to the vehicle over the bus."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from companion.control.modes import decode_set_mode, from_standard
from companion.link.codec import dialect as d
from companion.link.command_service import SET_MODE_MESSAGE, CommandArgs, Outcome
from companion.link.mode_messages import available_modes
from companion.link.telemetry import STREAMS
from companion.messages import CommandId, FlightMode

if TYPE_CHECKING:
    from companion.plugins.link.mavlink_link import MavlinkLink

BUS_ACK_TIMEOUT_S = 3.0
FORCE_DISARM = 21196
RELATIVE_FRAMES = frozenset(
    {
        d.MAV_FRAME_GLOBAL_RELATIVE_ALT,
        d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
    }
)


def register_commands(link: MavlinkLink) -> None:
    """Wire each supported MAV_CMD to its handler."""
    service = link.commands

    def arm_disarm(args: CommandArgs) -> Outcome:
        command = CommandId.START if args.params[0] >= 0.5 else CommandId.STOP
        control = link.snapshot.control
        in_air = control is not None and not control.landed
        if command == CommandId.STOP and in_air and round(args.params[1]) != FORCE_DISARM:
            # As ArduPilot and PX4: stopping the flight plug-ins in the air drops the
            # aircraft, so it takes the magic number to mean it.
            link.statustext("Disarm refused: flying (param2 21196 forces it)")
            return Outcome(d.MAV_RESULT_DENIED)
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
        if msg_id == d.MAVLINK_MSG_ID_AVAILABLE_MODES:
            modes = available_modes(link.mav, round(args.params[1]))
            return Outcome(extra=modes) if modes else Outcome(d.MAV_RESULT_DENIED)
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

    register_mode_commands(link)
    service.register(d.MAV_CMD_INJECT_FAILURE, lambda args: inject_failure(link, args))
    service.register(d.MAV_CMD_COMPONENT_ARM_DISARM, arm_disarm)
    service.register(d.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN, reboot)
    service.register(d.MAV_CMD_REQUEST_MESSAGE, request_message)
    service.register(d.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES, capabilities)
    service.register(d.MAV_CMD_SET_MESSAGE_INTERVAL, set_interval)
    service.register(d.MAV_CMD_GET_MESSAGE_INTERVAL, get_interval)


def inject_failure(link: MavlinkLink, args: CommandArgs) -> Outcome:
    """MAV_CMD_INJECT_FAILURE, as PX4: off unless SYS_FAILURE_EN is 1; the simulator
    bridge applies it to its emulated devices and answers (UNSUPPORTED for what it cannot)."""
    if link.store.get("SYS_FAILURE_EN") < 0.5:
        link.statustext("Failure injection is off (set SYS_FAILURE_EN to 1)")
        return Outcome(d.MAV_RESULT_DENIED)
    if link.ctx.vehicle.get("clock") != "sim":
        link.statustext("Failure injection needs the simulator")
        return Outcome(d.MAV_RESULT_UNSUPPORTED)
    params = tuple(float(round(v)) for v in args.params[:3])
    seq = link.publish_command(CommandId.INJECT_FAILURE, params)
    return Outcome(defer_seq=seq, timeout_s=BUS_ACK_TIMEOUT_S)


def register_mode_commands(link: MavlinkLink) -> None:
    """Mode commands go to the commander plug-in (UNSUPPORTED when the vehicle has none)."""
    service = link.commands
    px4 = link.identity.autopilot == d.MAV_AUTOPILOT_PX4

    def to_commander(command: CommandId, params: tuple[float, ...] = ()) -> Outcome:
        if not link.has_commander():
            return Outcome(d.MAV_RESULT_UNSUPPORTED)
        return Outcome(defer_seq=link.publish_command(command, params), timeout_s=BUS_ACK_TIMEOUT_S)

    def set_mode(mode: FlightMode | None, what: str) -> Outcome:
        if mode is None:
            link.statustext(f"{what}: unknown mode")
            return Outcome(d.MAV_RESULT_DENIED)
        return to_commander(CommandId.SET_MODE, (float(mode),))

    def do_set_mode(args: CommandArgs) -> Outcome:
        base, custom, sub = (round(v) for v in args.params[:3])
        return set_mode(decode_set_mode(base, custom, sub, px4), "Set mode")

    def set_standard_mode(args: CommandArgs) -> Outcome:
        return set_mode(from_standard(round(args.params[0])), "Set standard mode")

    def mission_start(args: CommandArgs) -> Outcome:
        return to_commander(CommandId.MISSION_START, args.params[:2])

    def rtl(args: CommandArgs) -> Outcome:
        return to_commander(CommandId.RETURN_TO_LAUNCH)

    def point(args: CommandArgs) -> tuple[float, float, float]:
        """(lat, lon, alt AMSL) of params 5-7; NaN where not given (0, 0 = here)."""
        lat, lon, alt = args.params[4:7]
        if not (math.isfinite(lat) and math.isfinite(lon)) or (lat == 0 and lon == 0):
            return (math.nan, math.nan, math.nan)
        status = link.snapshot.status
        if args.frame in RELATIVE_FRAMES and status is not None and status.home_valid:
            alt += status.home_alt_msl_m
        return (lat, lon, alt if math.isfinite(alt) else math.nan)

    def reposition(args: CommandArgs) -> Outcome:
        target = point(args)
        if not math.isfinite(target[0]):
            link.statustext("Go to: no position given")
            return Outcome(d.MAV_RESULT_DENIED)
        return to_commander(CommandId.REPOSITION, target)

    def loiter(args: CommandArgs) -> Outcome:
        return to_commander(CommandId.LOITER, point(args))

    def set_home(args: CommandArgs) -> Outcome:
        return to_commander(CommandId.SET_HOME, args.params)

    def set_mode_message(args: CommandArgs) -> Outcome:
        base, custom = round(args.params[0]), round(args.params[1])
        return set_mode(decode_set_mode(base, custom, 0, px4), "SET_MODE")

    service.register(d.MAV_CMD_DO_SET_MODE, do_set_mode)
    service.register(d.MAV_CMD_DO_SET_STANDARD_MODE, set_standard_mode)
    service.register(SET_MODE_MESSAGE, set_mode_message)
    service.register(d.MAV_CMD_MISSION_START, mission_start)
    service.register(d.MAV_CMD_NAV_RETURN_TO_LAUNCH, rtl)
    service.register(d.MAV_CMD_DO_REPOSITION, reposition)
    service.register(d.MAV_CMD_NAV_LOITER_UNLIM, loiter)
    service.register(d.MAV_CMD_DO_SET_HOME, set_home)
