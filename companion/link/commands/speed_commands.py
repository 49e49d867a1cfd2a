"""MAV_CMD_DO_CHANGE_SPEED: the airspeed the aircraft flies, as PX4 takes it.

param1 the speed type: 0 airspeed and 1 ground speed (MAVSDK's ``set_current_speed``
sends 1) are both flown as the airspeed demand, as PX4's navigator does; 2 and 3 (climb
and descent speeds) are refused: the energy controller sets those. param2 the speed in
m/s: -1 no change, -2 back to the default; any other value must lie within the airframe's
AIRSPEED_MIN and AIRSPEED_MAX, else DENIED with the reason. param3, the throttle, is left
to the energy controller (accepted, not applied). The speed holds until the mode changes
(but for a take-off's end in Hold) or the aircraft is disarmed; the commander keeps it.
"""

from __future__ import annotations

import math

from companion.link.codec import dialect as d
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands.port import BUS_ACK_TIMEOUT_S, VehiclePort, refuse
from companion.link.params_service import ParamsService
from companion.messages import CommandId

NO_CHANGE, DEFAULT = -1.0, -2.0
LIMITS = ("AIRSPEED_MIN", "AIRSPEED_MAX")  # the flight controller's


class SpeedCommands:
    """DO_CHANGE_SPEED."""

    def __init__(self, port: VehiclePort, params: ParamsService | None) -> None:
        self.port = port
        self.params = params
        self.service: CommandService | None = None

    def register(self, service: CommandService) -> None:
        self.service = service
        service.register(d.MAV_CMD_DO_CHANGE_SPEED, self.change_speed)

    def limits(self) -> tuple[float, float] | None:
        """The airframe's airspeed range, as the vehicle's parameters say (None: no flight
        controller declares it, so no speed can be flown)."""
        store = self.params.store if self.params is not None else None
        if store is None or any(name not in store.decls for name in LIMITS):
            return None
        low, high = (store.get(name) for name in LIMITS)
        return low, high

    def change_speed(self, args: CommandArgs) -> Outcome:
        kind, speed = round(args.params[0]), args.params[1]
        if kind not in (d.SPEED_TYPE_AIRSPEED, d.SPEED_TYPE_GROUNDSPEED):
            return refuse(self.port, self.service, "Change speed: climb and descent speeds not set")
        limits = self.limits()
        if limits is None or not self.port.has_commander():
            return Outcome(d.MAV_RESULT_UNSUPPORTED)
        if speed == NO_CHANGE:
            return Outcome(d.MAV_RESULT_ACCEPTED)
        low, high = limits
        if speed != DEFAULT and not low <= speed <= high:
            text = f"Change speed: {speed:g} m/s outside AIRSPEED_MIN..MAX {low:g}..{high:g}"
            return refuse(self.port, self.service, text)
        airspeed = math.nan if speed == DEFAULT else speed
        seq = self.port.publish_command(CommandId.CHANGE_SPEED, (airspeed,))
        return Outcome(defer_seq=seq, timeout_s=BUS_ACK_TIMEOUT_S)
