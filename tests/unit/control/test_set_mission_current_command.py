"""MISSION_SET_CURRENT / DO_SET_MISSION_CURRENT at the commander: accepted for an item the
mission has, counted and told to the flight controller in the status (``mission_jumps``,
``mission_jump_to``), kept in the flight state across a restart; refused beyond the
mission, and on the ground beyond the take-off (it would never be flown)."""

from __future__ import annotations

import json
import math

import pytest

from companion.control.commander import Commander
from companion.control.flight_state import FlightState, load_flight_state, save_flight_state
from companion.messages import CommandId, CommandResult, FlightMode, VehicleCommand

HOME = (-37.9105, 145.134, 81.3)


def _commander(count: int = 5, takeoff: int = 0, *, flying: bool = True) -> Commander:
    c = Commander(lambda: count, mission_takeoff=lambda: takeoff)
    c.home = c.position = HOME
    c.armed, c.landed = flying, False
    return c


def _send(c: Commander, command: CommandId, *params: float):
    decision = c.handle(VehicleCommand(command=int(command), param=(*params, *[0.0] * 7)[:7]))
    assert decision is not None
    return decision


def test_in_the_air_the_item_is_accepted_counted_and_told_to_the_controller():
    c = _commander()
    assert _send(c, CommandId.SET_MISSION_CURRENT, 3).result == CommandResult.ACCEPTED
    status = c.status(0)
    assert (status.mission_jumps, status.mission_jump_to, status.mission_first) == (1, 3, 3)
    assert status.changes == 0  # not a change of mode: the mode flown goes on
    assert _send(c, CommandId.SET_MISSION_CURRENT, 3).result == CommandResult.ACCEPTED
    assert c.status(0).mission_jumps == 2  # the same item again is a jump again


@pytest.mark.parametrize(
    ("count", "item", "text"),
    [
        (5, 5, "no item 5 (the mission has 5 items)"),
        (5, -1, "no item -1"),
        (5, math.nan, "no item -1"),
        (0, 0, "no item 0 (no mission stored)"),
    ],
)
def test_an_item_the_mission_lacks_is_refused_and_not_counted(count, item, text):
    c = _commander(count)
    decision = _send(c, CommandId.SET_MISSION_CURRENT, item)
    assert decision.result == CommandResult.DENIED
    assert text in decision.reason
    assert (c.status(0).mission_jumps, c.status(0).mission_jump_to) == (0, -1)


@pytest.mark.parametrize("armed", [False, True], ids=["disarmed", "armed-on-the-runway"])
def test_on_the_ground_an_item_beyond_the_take_off_is_refused(armed):
    c = _commander(takeoff=1, flying=armed)
    c.landed = armed
    decision = _send(c, CommandId.SET_MISSION_CURRENT, 2)
    assert decision.result == CommandResult.DENIED
    assert "skips the take-off (item 1) on the ground" in decision.reason
    assert c.status(0).mission_jumps == 0
    for item in (0, 1):  # up to the take-off itself: nothing skipped
        assert _send(c, CommandId.SET_MISSION_CURRENT, item).result == CommandResult.ACCEPTED
    assert c.status(0).mission_jump_to == 1


def test_on_the_ground_a_mission_without_a_take_off_may_start_anywhere():
    c = _commander(takeoff=-1, flying=False)
    assert _send(c, CommandId.SET_MISSION_CURRENT, 4).result == CommandResult.ACCEPTED


def test_mission_start_param1_as_px4_an_item_is_a_jump_else_the_item_set_before():
    c = _commander()
    assert _send(c, CommandId.SET_MISSION_CURRENT, 3).result == CommandResult.ACCEPTED
    assert _send(c, CommandId.MISSION_START, math.nan).result == CommandResult.ACCEPTED
    status = c.status(0)
    assert status.mode == FlightMode.MISSION
    assert (status.mission_first, status.mission_jumps) == (3, 1)  # starts where it was set
    assert _send(c, CommandId.MISSION_START, -1).result == CommandResult.ACCEPTED
    assert (c.status(0).mission_first, c.status(0).mission_jumps) == (3, 1)
    assert _send(c, CommandId.MISSION_START, 2).result == CommandResult.ACCEPTED
    status = c.status(0)
    assert (status.mission_first, status.mission_jumps, status.mission_jump_to) == (2, 2, 2)


def test_the_count_and_the_item_survive_a_restart_of_the_commander(tmp_path):
    c = _commander()
    _send(c, CommandId.SET_MODE, float(FlightMode.MISSION))
    _send(c, CommandId.SET_MISSION_CURRENT, 3)
    _send(c, CommandId.SET_MISSION_CURRENT, 4)
    save_flight_state(tmp_path, c.snapshot())
    saved = load_flight_state(tmp_path)
    assert saved is not None
    assert (saved.mission_jumps, saved.mission_jump_to) == (2, 4)
    again = _commander()
    again.restore(saved)
    status = again.status(0)
    assert (status.mission_jumps, status.mission_jump_to, status.mission_first) == (2, 4, 4)


def test_an_older_flight_state_without_them_reads_as_no_jump(tmp_path):
    state = FlightState(True, int(FlightMode.MISSION), HOME, (math.nan,) * 3, math.nan, 2, 7, 0)
    data = json.loads(state.to_json())
    del data["mission_jumps"], data["mission_jump_to"]
    (tmp_path / "flight_state.json").write_text(json.dumps(data))
    saved = load_flight_state(tmp_path)
    assert saved is not None
    assert (saved.mission_seq, saved.mission_jumps, saved.mission_jump_to) == (2, 0, -1)
