"""A mission's NAV_RETURN_TO_LAUNCH hands the flight to Return, as ArduPlane and PX4 do.

The controller's executor ends the mission on that item, reached as it is begun
(``mission.executor``); the commander then enters Return, so the aircraft goes where
Return goes (the nearer rally point, else home; ``RTL_AUTOLAND``'s landing) and a ground
station shows the mode it flies. It enters it once per entry of Mission: the controller's
status says which entry it flew (the vehicle status's ``changes`` echoed), so a status from
before a MISSION_START or a jump never sends a new mission home. Back in Mission on that
item, Return is entered again, as ArduPlane does; a set-current elsewhere flies on.
"""

from __future__ import annotations

from collections.abc import Sequence

from companion.control.mission.items import MissionItem
from companion.messages import ControlStatus, FlightMode, MissionState
from mavlink_dialect import companion as d


def returning_item(
    items: Sequence[MissionItem],
    control: ControlStatus | None,
    mode: FlightMode,
    changes: int,
    landed: bool,
) -> int | None:
    """The NAV_RETURN_TO_LAUNCH item (its seq) the controller has ended the mission on in
    this entry of Mission, flying; None otherwise. ``control``: its fresh status, or None."""
    if control is None or mode != FlightMode.MISSION or landed:
        return None
    if control.mission_state != MissionState.COMPLETE or control.mode_changes != changes:
        return None
    seq = int(control.mission_seq)
    if 0 <= seq < len(items) and items[seq].command == d.MAV_CMD_NAV_RETURN_TO_LAUNCH:
        return seq
    return None


def reported_state(
    flying_it: bool, finished_now: bool, finished: bool, in_return: bool, set_pending: bool
) -> MissionState:
    """The controller's MissionState for its status: ACTIVE while it flies the mission
    (``flying_it``: an executor, in Mission), COMPLETE once it is flown to its end
    (``finished_now``) and on through the Return it then flies (``finished``,
    ``in_return``, no set-current waiting to take it up again). The commander enters
    Return within a step of the first COMPLETE, and a link reading the newest status ten
    times a second at lockstep speed missed that one: MISSION_CURRENT never said COMPLETE
    and MAVSDK's ``is_mission_finished`` never came true (CI)."""
    if finished_now or (finished and in_return and not set_pending):
        return MissionState.COMPLETE
    return MissionState.ACTIVE if flying_it else MissionState.NOT_STARTED
