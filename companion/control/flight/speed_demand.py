"""The airspeed the energy controller is asked for, and what a commanded speed changes.

A mission's DO_CHANGE_SPEED gives its setpoints their own speed; the command
DO_CHANGE_SPEED (MAVSDK's ``set_current_speed``) comes in the vehicle status and holds in
its mode (the commander forgets it on a change of mode and at disarming, as PX4's
navigator does). Whichever came last is flown: a new command overrides the mission's speed
until the mission's next DO_CHANGE_SPEED. Every demand is bounded by AIRSPEED_MIN and
AIRSPEED_MAX; the landing approach alone flies slower (TECS_LAND_ARSPD).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from companion.control.mission.executor import MissionExecutor, Setpoint


class CommandedSpeed:
    """The commanded airspeed as the vehicle status says it (NaN: none)."""

    def __init__(self) -> None:
        self.value = math.nan

    def follow(self, status_speed: float, executor: MissionExecutor | None) -> None:
        """Take up the status's speed; a new one overrides the running mission's own."""
        speed = status_speed if math.isfinite(status_speed) and status_speed > 0 else math.nan
        if speed == self.value or (math.isnan(speed) and math.isnan(self.value)):
            return
        self.value = speed
        if executor is not None and math.isfinite(speed):
            executor.speed = math.nan  # until the mission's next DO_CHANGE_SPEED


def speed_demand(
    sp: Setpoint, commanded: float, cfg: Mapping[str, float], least_speed: float = math.inf
) -> tuple[float, float]:
    """(airspeed demand, least airspeed allowed) for flying ``sp``: its own speed, else
    the commanded one, else the cruise airspeed, within the airframe's limits."""
    if math.isfinite(sp.speed):
        speed = sp.speed
    elif math.isfinite(commanded):
        speed = commanded
    else:
        speed = cfg["AIRSPEED_CRUISE"]
    if sp.approach:  # slowed and configured before the final: no speed left to lose on it
        speed = least_speed = cfg["TECS_LAND_ARSPD"]
    # The landing approach alone may fly slower than AIRSPEED_MIN.
    speed_min = min(cfg["AIRSPEED_MIN"], least_speed)
    return max(speed_min, min(cfg["AIRSPEED_MAX"], speed)), speed_min
