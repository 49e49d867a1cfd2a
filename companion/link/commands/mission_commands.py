"""Commands about the stored mission: DO_SET_MISSION_CURRENT and DO_PAUSE_CONTINUE.

DO_SET_MISSION_CURRENT (MAVProxy's ``wp set N``) does what the MISSION_SET_CURRENT message
does: param1 the item (-1: keep the current one), refused beyond the mission; param2
(reset) needs nothing more, as making an item current already clears "complete". The
commander decides (``Commander._set_current``): a mission flying goes to the item at once,
another mode enters the mission there; refused on the ground beyond the take-off. The
answer waits for it, as for the other commander commands; MISSION_CURRENT follows.

DO_PAUSE_CONTINUE, as ArduPlane takes it: param1 0 pauses (what QGroundControl's Pause
does: circle here, or keep the point a go-to flies to), 1 continues the mission left
before its end, from the item it was at. Refused with the reason on the ground, and a
continue with no mission left unfinished (a mission already flown goes on: accepted).
"""

from __future__ import annotations

import math

from companion.link.codec import dialect as d
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands.port import BUS_ACK_TIMEOUT_S, VehiclePort, flying, refuse
from companion.link.microservice import Outgoing
from companion.link.mission_service import MissionService
from companion.messages import CommandId, FlightMode

PAUSE, CONTINUE = 0, 1


class MissionCommands:
    """DO_SET_MISSION_CURRENT and DO_PAUSE_CONTINUE."""

    def __init__(self, port: VehiclePort, missions: MissionService) -> None:
        self.port = port
        self.missions = missions
        self.service: CommandService | None = None
        missions.ask_commander = self.ask_commander  # MISSION_SET_CURRENT, the message

    def register(self, service: CommandService) -> None:
        self.service = service
        service.register(d.MAV_CMD_DO_SET_MISSION_CURRENT, self.set_current)
        service.register(d.MAV_CMD_DO_PAUSE_CONTINUE, self.pause_continue)

    def set_current(self, args: CommandArgs) -> Outcome:
        """Item param1 becomes current; MISSION_CURRENT tells every ground station."""
        seq = round(args.params[0])
        seq = self.missions.current if seq == -1 else seq
        total = len(self.missions.store.items[d.MAV_MISSION_TYPE_MISSION])
        if 0 <= seq < total and round(args.params[0]) != -1 and self.port.has_commander():
            return self._commander(CommandId.SET_MISSION_CURRENT, (float(seq),))
        if not self.missions.set_current(seq):
            what = "no mission stored" if total == 0 else f"the mission has {total} items"
            return refuse(self.port, self.service, f"Set mission item: no item {seq} ({what})")
        return Outcome(extra=[Outgoing(self.missions.mission_current(), None)])

    def ask_commander(self, seq: int) -> bool:
        """MISSION_SET_CURRENT's item for the commander; False when none runs."""
        if not self.port.has_commander():
            return False
        self.port.publish_command(CommandId.SET_MISSION_CURRENT, (float(seq),))
        return True

    def pause_continue(self, args: CommandArgs) -> Outcome:
        """Pause (0): hold here; continue (1): the mission again from where it was left."""
        what = "Pause" if round(args.params[0]) == PAUSE else "Continue"
        if not self.port.has_commander():
            return Outcome(d.MAV_RESULT_UNSUPPORTED)
        if not flying(self.port):
            return refuse(self.port, self.service, f"{what}: not flying")
        if what == "Pause":  # no point, no height: QGroundControl's Pause, the same rules
            return self._commander(CommandId.REPOSITION, (math.nan,) * 3)
        snap = self.port.snapshot
        if snap.status is not None and snap.status.mode == FlightMode.MISSION:
            return Outcome(d.MAV_RESULT_ACCEPTED)  # flying it already
        if not snap.mission_paused:
            return refuse(self.port, self.service, "Continue: no mission left to continue")
        return self._commander(CommandId.SET_MODE, (float(FlightMode.MISSION),))

    def _commander(self, command: CommandId, params: tuple[float, ...]) -> Outcome:
        seq = self.port.publish_command(command, params)
        return Outcome(defer_seq=seq, timeout_s=BUS_ACK_TIMEOUT_S)
