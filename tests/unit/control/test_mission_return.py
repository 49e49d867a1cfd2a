"""A mission's NAV_RETURN_TO_LAUNCH: the commander enters Return on it, once per entry of
Mission, as ArduPlane and PX4 switch to their RTL / Return mode there."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from companion.control.commander import Commander
from companion.control.mission_return import reported_state, returning_item
from companion.messages import ControlStatus, FlightMode, MissionState
from companion.plugins.vehicle.commander import CommanderPlugin
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import item, wp

HOME = (-37.9105, 145.134, 50.0)
ITEMS = [wp(0, (1_000.0, 0.0)), wp(1, (1_000.0, 1_000.0)), item(2, d.MAV_CMD_NAV_RETURN_TO_LAUNCH)]


def _control(seq: int = 2, state: MissionState = MissionState.COMPLETE, changes: int = 7):
    return ControlStatus(t_us=1, mission_seq=seq, mission_state=state, mode_changes=changes)


def test_the_controller_ending_the_mission_on_its_rtl_item_is_a_return():
    assert returning_item(ITEMS, _control(), FlightMode.MISSION, 7, landed=False) == 2


@pytest.mark.parametrize(
    ("control", "mode", "landed", "why"),
    [
        (_control(changes=6), FlightMode.MISSION, False, "a status from before MISSION_START"),
        (_control(state=MissionState.ACTIVE), FlightMode.MISSION, False, "not yet on it"),
        (_control(), FlightMode.LOITER, False, "the operator has left Mission"),
        (_control(), FlightMode.MISSION, True, "on the ground"),
        (None, FlightMode.MISSION, False, "no controller running"),
        (_control(seq=1), FlightMode.MISSION, False, "finished on a waypoint: circles it"),
        (_control(seq=3), FlightMode.MISSION, False, "past the end of the plan"),
    ],
)
def test_anything_else_is_no_return(control, mode, landed, why):
    assert returning_item(ITEMS, control, mode, 7, landed) is None, why


def _plugin(commander: Commander, said: list[str]) -> SimpleNamespace:
    store = SimpleNamespace(items={d.MAV_MISSION_TYPE_MISSION: ITEMS})
    return SimpleNamespace(
        commander=commander, store=store, _say=lambda _t, text, _s: said.append(text)
    )


def test_the_commander_enters_return_once_and_says_why():
    commander = Commander(lambda: len(ITEMS))
    commander.home, commander.armed, commander.mode = HOME, True, FlightMode.MISSION
    commander.changes = 7
    said: list[str] = []
    plugin = _plugin(commander, said)
    assert CommanderPlugin._mission_return(plugin, 0, _control())  # type: ignore[arg-type]
    assert commander.mode == FlightMode.RTL and said == ["Mission: item 2 returns to launch"]
    # The controller's next status still says the mission ended there, in the old entry.
    assert not CommanderPlugin._mission_return(plugin, 0, _control())  # type: ignore[arg-type]
    assert commander.changes == 8 and said == ["Mission: item 2 returns to launch"]


def test_the_status_says_complete_through_the_return_the_mission_ended_in():
    """The commander enters Return within a step of the first COMPLETE; a link that reads
    the newest status missed it at lockstep speed. COMPLETE holds through that Return,
    until a set-current is waiting to take the mission up again."""
    state = reported_state
    assert state(True, False, False, False, False) == MissionState.ACTIVE
    assert state(True, True, True, False, False) == MissionState.COMPLETE  # its end, in Mission
    assert state(False, False, True, True, False) == MissionState.COMPLETE  # the Return after
    assert state(False, False, True, True, True) == MissionState.NOT_STARTED  # set elsewhere
    assert state(False, False, True, False, False) == MissionState.NOT_STARTED  # Loiter after
    assert state(False, False, False, True, False) == MissionState.NOT_STARTED  # a failsafe RTL
