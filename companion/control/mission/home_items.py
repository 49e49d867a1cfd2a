"""DO_SET_HOME in a mission, as ArduPlane and PX4 take it: param1 1 makes the aircraft's
place home, 0 the item's (its altitude above sea level, or above the present home in a
relative frame). The commander keeps home, so the item becomes its SET_HOME command, as
the command DO_SET_HOME from a ground station does; the mission then flies on from the
next item, its relative altitudes and Return measured from the new home.
"""

from __future__ import annotations

from companion.control.mission.executor import RELATIVE_FRAMES
from companion.control.mission.items import MissionItem
from companion.messages import MISSION_HOME_SEQ, CommandId, VehicleCommand


def set_home_command(item: MissionItem, t_us: int, home_alt_msl: float) -> VehicleCommand:
    """The commander's SET_HOME for a mission's DO_SET_HOME ``item`` (its parameters were
    checked at upload), with the present home's altitude ``home_alt_msl``."""
    cmd = VehicleCommand(t_us=t_us, seq=MISSION_HOME_SEQ, command=int(CommandId.SET_HOME))
    if round(item.param1) == 1:
        cmd.param[0] = 1.0
        return cmd
    alt = item.z + (home_alt_msl if item.frame in RELATIVE_FRAMES else 0.0)
    cmd.param[4], cmd.param[5], cmd.param[6] = item.x / 1e7, item.y / 1e7, alt
    return cmd
