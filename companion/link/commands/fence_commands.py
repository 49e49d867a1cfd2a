"""MAV_CMD_DO_FENCE_ENABLE: the geofence on or off, as writing FENCE_ENABLE does.

param1 1 enables and 0 disables the fence failsafe (the commander's FENCE_ENABLE, which
every ground station is told of in a PARAM_VALUE); 2, "disable the floor only", is
refused: the fence here has no floor. UNSUPPORTED on a vehicle without the parameter
(no commander to keep the fence).
"""

from __future__ import annotations

from companion.link.codec import dialect as d
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands.port import VehiclePort, refuse
from companion.link.params_service import ParamsService
from companion.params import ParamError

FENCE_ENABLE = "FENCE_ENABLE"  # the commander's (companion.control.failsafe)
DISABLE_FLOOR = 2


class FenceCommands:
    """DO_FENCE_ENABLE."""

    def __init__(self, port: VehiclePort, params: ParamsService | None) -> None:
        self.port = port
        self.params = params
        self.service: CommandService | None = None

    def register(self, service: CommandService) -> None:
        self.service = service
        service.register(d.MAV_CMD_DO_FENCE_ENABLE, self.fence_enable)

    def fence_enable(self, args: CommandArgs) -> Outcome:
        action = round(args.params[0])
        if self.params is None or FENCE_ENABLE not in self.params.store.decls:
            return Outcome(d.MAV_RESULT_UNSUPPORTED)
        if action == DISABLE_FLOOR:
            return refuse(self.port, self.service, "Fence: no floor to disable (it has none)")
        try:
            news = self.params.write(FENCE_ENABLE, float(action))
        except ParamError as exc:  # a range another declaration gave it
            return refuse(self.port, self.service, f"Fence: {exc}")
        state = "enabled" if action else "disabled"
        self.port.statustext(f"Fence {state}", d.MAV_SEVERITY_INFO)
        return Outcome(extra=news)  # PARAM_VALUE for every ground station
