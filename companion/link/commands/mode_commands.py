"""Mode and navigation commands: each goes to the commander plug-in, which owns the mode
and home (UNSUPPORTED when the vehicle has no commander)."""

from __future__ import annotations

import math

from companion.control.modes import decode_set_mode, from_standard
from companion.link.codec import dialect as d
from companion.link.command_rules import whole_or
from companion.link.command_service import SET_MODE_MESSAGE, CommandArgs, CommandService, Outcome
from companion.link.commands.port import BUS_ACK_TIMEOUT_S, VehiclePort
from companion.messages import CommandId, FlightMode

RELATIVE_FRAMES = frozenset(
    {
        d.MAV_FRAME_GLOBAL_RELATIVE_ALT,
        d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
    }
)


class ModeCommands:
    """DO_SET_MODE, DO_SET_STANDARD_MODE, SET_MODE, MISSION_START, RTL, DO_REPOSITION,
    NAV_LOITER_UNLIM, DO_ORBIT, NAV_TAKEOFF, NAV_LAND, DO_SET_HOME and DO_GO_AROUND."""

    def __init__(self, port: VehiclePort, autopilot: int) -> None:
        self.port = port
        self.px4 = autopilot == d.MAV_AUTOPILOT_PX4
        self.service: CommandService | None = None

    def register(self, service: CommandService) -> None:
        self.service = service
        service.register(d.MAV_CMD_DO_SET_MODE, self.do_set_mode)
        service.register(d.MAV_CMD_DO_SET_STANDARD_MODE, self.set_standard_mode)
        service.register(SET_MODE_MESSAGE, self.set_mode_message)
        service.register(d.MAV_CMD_MISSION_START, self.mission_start)
        service.register(d.MAV_CMD_NAV_RETURN_TO_LAUNCH, self.rtl)
        service.register(d.MAV_CMD_DO_REPOSITION, self.reposition)
        service.register(d.MAV_CMD_NAV_LOITER_UNLIM, self.loiter)
        service.register(d.MAV_CMD_DO_SET_HOME, self.set_home)
        service.register(d.MAV_CMD_DO_ORBIT, self.orbit)
        service.register(d.MAV_CMD_NAV_TAKEOFF, self.takeoff)
        service.register(d.MAV_CMD_NAV_LAND, self.land)
        service.register(d.MAV_CMD_DO_GO_AROUND, self.go_around)

    def to_commander(self, command: CommandId, params: tuple[float, ...] = ()) -> Outcome:
        if not self.port.has_commander():
            return Outcome(d.MAV_RESULT_UNSUPPORTED)
        seq = self.port.publish_command(command, params)
        return Outcome(defer_seq=seq, timeout_s=BUS_ACK_TIMEOUT_S)

    def _refuse(self, text: str) -> None:
        """A refusal like a broken rule's: counted, and said at most a few times a second
        (a flood of SET_MODE had told every link some 500 STATUSTEXT a second)."""
        if self.service is None:
            self.port.statustext(text)
            return
        self.service.refused += 1
        self.service.on_refusal(text)

    def set_mode(self, mode: FlightMode | None, what: str) -> Outcome:
        if mode is None:
            self._refuse(f"{what}: unknown mode")
            return Outcome(d.MAV_RESULT_DENIED)
        return self.to_commander(CommandId.SET_MODE, (float(mode),))

    def do_set_mode(self, args: CommandArgs) -> Outcome:
        base, custom, sub = args.params[:3]
        base, custom, sub = round(base), whole_or(custom, 0), whole_or(sub, 0)
        return self.set_mode(decode_set_mode(base, custom, sub, self.px4), "Set mode")

    def set_standard_mode(self, args: CommandArgs) -> Outcome:
        return self.set_mode(from_standard(round(args.params[0])), "Set standard mode")

    def set_mode_message(self, args: CommandArgs) -> Outcome:
        base, custom = round(args.params[0]), round(args.params[1])
        return self.set_mode(decode_set_mode(base, custom, 0, self.px4), "SET_MODE")

    def mission_start(self, args: CommandArgs) -> Outcome:
        # param1 as PX4's: an item starts there, NaN or -1 the item set current or left at.
        first, last = whole_or(args.params[0], -1), whole_or(args.params[1], -1)
        return self.to_commander(CommandId.MISSION_START, (float(first), float(last)))

    def go_around(self, args: CommandArgs) -> Outcome:
        return self.to_commander(CommandId.GO_AROUND)

    def rtl(self, args: CommandArgs) -> Outcome:
        return self.to_commander(CommandId.RETURN_TO_LAUNCH)

    def reposition(self, args: CommandArgs) -> Outcome:
        """Go to a point; without one (NaN latitude and longitude, as QGroundControl's
        Pause and Change altitude send it) hold here or keep the point, at the altitude."""
        return self.to_commander(CommandId.REPOSITION, self.point(args))

    def loiter(self, args: CommandArgs) -> Outcome:
        return self.to_commander(CommandId.LOITER, self.point(args))

    def orbit(self, args: CommandArgs) -> Outcome:
        """Circle a point (here when none is given); radius param1, NaN or 0: the default."""
        radius = args.params[0]
        radius = math.nan if not math.isfinite(radius) or radius == 0 else radius
        return self.to_commander(CommandId.ORBIT, (*self.point(args), radius))

    def takeoff(self, args: CommandArgs) -> Outcome:
        """Take off and climb to param7 (AMSL, or above home in a relative frame)."""
        return self.to_commander(CommandId.TAKEOFF, (math.nan, math.nan, self.point(args)[2]))

    def land(self, args: CommandArgs) -> Outcome:
        """Land now (MAVSDK's land(): no position): the Land mode, which flies the mission's
        landing, else lands back on the take-off runway. A fixed wing cannot land on a point
        it is given (it needs a runway and an approach to it): refused with the reason."""
        lat, lon, _ = self.point(args)
        if math.isfinite(lat) or math.isfinite(lon):
            self._refuse("Land: no landing at a given point; send it without one (runway)")
            return Outcome(d.MAV_RESULT_DENIED)
        return self.set_mode(FlightMode.LAND, "Land")

    def set_home(self, args: CommandArgs) -> Outcome:
        use_current = float(whole_or(args.params[0], 0))
        return self.to_commander(CommandId.SET_HOME, (use_current, *args.params[1:]))

    def point(self, args: CommandArgs) -> tuple[float, float, float]:
        """(lat, lon, alt AMSL) of params 5-7; NaN where not given.

        Latitude and longitude 0, 0 mean "here" and altitude 0 "the present altitude", as
        ArduPilot reads them: a command sent with every parameter 0 (QGroundControl's custom
        actions, MAVProxy's defaults) names no point, and read as 0 m above sea level it
        had sent the aircraft into the ground. The commander refuses a real altitude under
        its floor (GUIDED_ALT_MIN above home)."""
        lat, lon, alt = args.params[4:7]
        if not (math.isfinite(lat) and math.isfinite(lon)) or (lat == 0 and lon == 0):
            lat = lon = math.nan
        if alt == 0:
            alt = math.nan
        status = self.port.snapshot.status
        if args.frame in RELATIVE_FRAMES and status is not None and status.home_valid:
            alt += status.home_alt_msl_m
        return (lat, lon, alt if math.isfinite(alt) else math.nan)
