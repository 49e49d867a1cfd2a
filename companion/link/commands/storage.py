"""MAV_CMD_PREFLIGHT_STORAGE: parameters back to their defaults.

param1, as the MAVLink spec numbers it: 0 read and 1 write the stored parameters (accepted
and nothing to do: every value is stored atomically as it is set), 2 reset every parameter
to its default (QGroundControl's Parameters page, Tools → "Reset all to firmware's
defaults", sends it and then reads the whole list again), 3 reset the sensor calibration
(the Sensors page's "Factory reset": the IMU's offsets and trims, "Reset successful" once
ACCEPTED), 4 reset everything, which here is 2 (the vehicle keeps no operation counters in
its parameters). param2, the mission storage, is ignored: missions are stored as they are
uploaded and cleared with MISSION_CLEAR_ALL. Refused while armed, as the values change
under the flight plug-ins. The Parameters page's other item, "Reset to vehicle's
configuration defaults", writes PX4's SYS_AUTOCONFIG = 2, which does the same reset.
"""

from __future__ import annotations

from companion.link.calibration_service import Calibration
from companion.link.codec import dialect as d
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands.port import VehiclePort, armed
from companion.link.params_service import ParamsService
from companion.params import ParamError

READ, WRITE = d.PARAM_READ_PERSISTENT, d.PARAM_WRITE_PERSISTENT
RESET_ALL = (d.PARAM_RESET_FACTORY_DEFAULT, d.PARAM_RESET_ALL_DEFAULT)
AUTOCONFIG = "SYS_AUTOCONFIG"  # PX4's, written by QGroundControl's other reset


class StorageCommands:
    """PREFLIGHT_STORAGE for the parameters and the sensor calibration kept in them."""

    def __init__(self, port: VehiclePort, params: ParamsService, calibration: Calibration) -> None:
        self.port = port
        self.params = params
        self.calibration = calibration

    def register(self, service: CommandService) -> None:
        service.register(d.MAV_CMD_PREFLIGHT_STORAGE, self.storage)
        if AUTOCONFIG in self.params.store.decls:
            self.params.actions[AUTOCONFIG] = self._autoconfig

    def _busy(self) -> bool:
        """Armed, or a calibration under way: the values must not change under them."""
        return armed(self.port) or self.calibration.running

    def _autoconfig(self, value: float) -> None:
        """PX4's SYS_AUTOCONFIG written 2: the same reset, asked through a parameter."""
        if value == 0.0:
            return
        if self._busy():
            raise ParamError(f"{AUTOCONFIG}: disarm first, with no calibration running")
        self._reset_all()

    def storage(self, args: CommandArgs) -> Outcome:
        action = round(args.params[0])
        if action in (READ, WRITE):
            return Outcome(d.MAV_RESULT_ACCEPTED)
        if self._busy():
            self.port.statustext("Parameter reset: disarm first, with no calibration running")
            return Outcome(d.MAV_RESULT_DENIED)
        if action == d.PARAM_RESET_SENSOR_DEFAULT:
            self.calibration.reset()
            return Outcome(d.MAV_RESULT_ACCEPTED)
        if action not in RESET_ALL:
            return Outcome(d.MAV_RESULT_UNSUPPORTED)
        self._reset_all()
        return Outcome(d.MAV_RESULT_ACCEPTED)

    def _reset_all(self) -> None:
        changed = self.params.reset()
        later = [n for n in changed if self.params.store.decls[n].reboot_required]
        after = f", {len(later)} after a reboot" if later else ""
        self.port.statustext(
            f"Parameters reset to defaults: {len(changed)} changed{after}", d.MAV_SEVERITY_NOTICE
        )
