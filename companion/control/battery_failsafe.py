"""The low-battery failsafe: what the vehicle does when the gauge says the pack runs out.

Pure: the battery level (``sensors/battery``, judged by the battery plug-in against its
BATT_* thresholds) and whether the aircraft flies in; actions out, as in
``companion.control.failsafe``. As ArduPlane: each level is announced once when it is first
reached, and its action (BATT_FS_LOW_ACT, BATT_FS_CRT_ACT: 0 warn only, 1 Return) is taken
once, the first time the level holds while flying; the operator may take the aircraft back
afterwards (a pack does not recharge, so there is nothing to re-assert).
"""

from __future__ import annotations

from companion.control.failsafe import Action
from companion.messages import BatteryLevel, FlightMode
from companion.params import ParamDecl
from mavlink_dialect import companion as d

BATTERY_FS_PARAMS = (
    ParamDecl.switch(
        "BATT_FS_LOW_ACT", 1.0, "On low battery: 0 warn only, 1 return home", "Warn", "Return"
    ),
    ParamDecl.switch(
        "BATT_FS_CRT_ACT", 1.0, "On critical battery: 0 warn, 1 return home", "Warn", "Return"
    ),
)
NAMES = {BatteryLevel.LOW: "low", BatteryLevel.CRITICAL: "critical"}
ACTION_PARAM = {BatteryLevel.LOW: "BATT_FS_LOW_ACT", BatteryLevel.CRITICAL: "BATT_FS_CRT_ACT"}


class BatteryFailsafe:
    """Remembers which battery levels were announced and acted on."""

    def __init__(self, params: dict[str, float]) -> None:
        self.params = params
        self.announced = BatteryLevel.OK
        self.acted = BatteryLevel.OK

    def step(self, level: int | None, flying: bool) -> list[Action]:
        if level not in NAMES:
            return []
        level = BatteryLevel(level)
        act = self.params[ACTION_PARAM[level]] >= 0.5
        if flying and act and level > self.acted:
            self.acted = self.announced = level
            return [Action(FlightMode.RTL, f"Failsafe: battery {NAMES[level]}, returning home")]
        if level > self.announced:
            self.announced = level
            severity = d.MAV_SEVERITY_CRITICAL if act or flying else d.MAV_SEVERITY_WARNING
            return [Action(None, f"Battery {NAMES[level]}", severity)]
        return []
