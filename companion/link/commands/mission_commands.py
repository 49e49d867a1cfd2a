"""Commands about the stored mission: DO_SET_MISSION_CURRENT and DO_PAUSE_CONTINUE.

DO_SET_MISSION_CURRENT (MAVProxy's ``wp set N``) does what the MISSION_SET_CURRENT message
does: param1 the item (-1: keep the current one), refused beyond the mission; param2
(reset) needs nothing more, as making an item current already clears "complete".
"""

from __future__ import annotations

from companion.link.codec import dialect as d
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands.port import VehiclePort, refuse
from companion.link.microservice import Outgoing
from companion.link.mission_service import MissionService


class MissionCommands:
    """DO_SET_MISSION_CURRENT."""

    def __init__(self, port: VehiclePort, missions: MissionService) -> None:
        self.port = port
        self.missions = missions
        self.service: CommandService | None = None

    def register(self, service: CommandService) -> None:
        self.service = service
        service.register(d.MAV_CMD_DO_SET_MISSION_CURRENT, self.set_current)

    def set_current(self, args: CommandArgs) -> Outcome:
        """Item param1 becomes current; MISSION_CURRENT tells every ground station."""
        seq = round(args.params[0])
        seq = self.missions.current if seq == -1 else seq
        total = len(self.missions.store.items[d.MAV_MISSION_TYPE_MISSION])
        if not self.missions.set_current(seq):
            what = "no mission stored" if total == 0 else f"the mission has {total} items"
            return refuse(self.port, self.service, f"Set mission item: no item {seq} ({what})")
        return Outcome(extra=[Outgoing(self.missions.mission_current(), None)])
