"""Generic payload outputs (DO_SET_ACTUATOR), as a PX4 user works them: ACT_SETn_OUT wires
actuator set n to a servo card output; QGroundControl's "Set actuator" item and MAVSDK's
``Action.set_actuator`` set the sets from -1 to 1, and the servo output gets 1000-2000 µs.
A set not wired is passed over; a command that reaches no output, or would move a
surface's, moves nothing and the operator is told why."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from companion.control.mission.actuator_sets import ACTUATOR_PARAMS, ActuatorSets
from companion.control.mission.items import MissionItem, check_item, check_mission
from companion.messages import ACTUATOR_SEQ, CommandId, VehicleCommand
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import HOME_ALT, executor, item, wp

SURFACES = {1: "aileron", 2: "elevator", 3: "rudder", 4: "throttle", 5: "flaps", 6: "brakes"}
DEFAULTS = {p.name: p.default for p in ACTUATOR_PARAMS}
NAN = math.nan


def set_actuator(seq: int, *values: float, index: float = 0.0) -> MissionItem:
    """As QGroundControl 4.4.5 sends "Set actuator": param1-4 actuators 1-4 (NaN: leave
    it), sets 5 and 6 in x and y scaled by 1e7 (0: it shows no field for them), param7 the
    index, frame MISSION."""
    p = [*values, *[NAN] * (4 - len(values))]
    base = item(seq, d.MAV_CMD_DO_SET_ACTUATOR, p1=p[0], p2=p[1], p3=p[2])
    return replace(base, frame=d.MAV_FRAME_MISSION, param4=p[3], z=index)


def actuators(**params: float) -> tuple[ActuatorSets, list[VehicleCommand], list[str]]:
    sent: list[VehicleCommand] = []
    said: list[str] = []
    a = ActuatorSets(sent.append, lambda _t, _severity, text: said.append(text), SURFACES)
    a.configure({**DEFAULTS, **params})
    return a, sent, said


def pulses(sent: list[VehicleCommand]) -> list[tuple[int, int]]:
    assert all(c.command == CommandId.SET_SERVO and c.seq == ACTUATOR_SEQ for c in sent)
    return [(round(c.param[0]), round(c.param[1])) for c in sent]


def test_values_within_one_or_nan_are_accepted_at_upload_and_others_refused():
    assert check_item(set_actuator(0, 1.0, -1.0, 0.25), 1) == d.MAV_MISSION_ACCEPTED
    assert check_item(set_actuator(0), 1) == d.MAV_MISSION_ACCEPTED  # every set left
    refused = {
        set_actuator(0, 1.5): d.MAV_MISSION_INVALID_PARAM1,
        set_actuator(0, NAN, NAN, NAN, -2.0): d.MAV_MISSION_INVALID_PARAM4,
        set_actuator(0, math.inf): d.MAV_MISSION_INVALID_PARAM1,
        replace(set_actuator(0, 1.0), x=20_000_000): d.MAV_MISSION_INVALID_PARAM5_X,
        set_actuator(0, 1.0, index=1.0): d.MAV_MISSION_INVALID_PARAM7,
        set_actuator(0, 1.0, index=NAN): d.MAV_MISSION_INVALID_PARAM7,
    }
    for it, result in refused.items():
        assert check_item(it, 1) == result, it
    plan = [wp(0, (0.0, 1000.0)), set_actuator(1, 1.0), wp(2, (1000.0, 1000.0))]
    assert check_mission(plan) == d.MAV_MISSION_ACCEPTED


def test_the_executor_hands_it_out_as_it_passes_and_flies_on():
    move = set_actuator(1, 0.5)
    ex = executor([wp(0, (0.0, 1000.0)), move, wp(2, (1000.0, 1000.0))])
    ex.step((0.0, 10.0), HOME_ALT + 100.0, 0.0)
    assert ex.take_actions() == ([], [])
    ex.step((0.0, 1000.0), HOME_ALT + 100.0, 1.0)
    assert ex.current == 2 and ex.take_actions() == ([], [move])


def test_a_wired_set_goes_to_its_output_from_1000_to_2000_us_and_nan_leaves_it():
    a, sent, said = actuators(ACT_SET1_OUT=7, ACT_SET2_OUT=8)
    assert a.act(5, (1.0, -1.0, NAN, NAN, NAN, NAN), 0) is None
    assert a.act(6, (NAN, 0.0, NAN, NAN, NAN, NAN), 0) is None
    assert a.act(7, (0.25, NAN, NAN, NAN, NAN, NAN), 0) is None
    assert pulses(sent) == [(7, 2000), (8, 1000), (8, 1500), (7, 1625)]
    assert said[0] == "Set actuator: output 7 2000 us, output 8 1000 us"


def test_qgcs_item_passes_over_sets_not_wired_and_a_mission_is_told_when_none_is():
    a, sent, said = actuators(ACT_SET3_OUT=7)
    a.items(1, [set_actuator(4, NAN, NAN, -0.5)])  # sets 5 and 6 come as 0, not wired
    assert pulses(sent) == [(7, 1250)]
    a.items(2, [set_actuator(5, 1.0)])  # set 1 is not wired
    assert len(sent) == 1
    assert (
        said[-1]
        == "Mission: Set actuator: not wired (ACT_SET1_OUT, ACT_SET5_OUT, ACT_SET6_OUT are 0)"
    )


@pytest.mark.parametrize(
    ("params", "values", "index", "reason"),
    [
        ({}, (1.0, NAN, NAN, NAN, NAN, NAN), 0, "not wired (ACT_SET1_OUT is 0)"),
        ({}, (NAN,) * 6, 0, "no value given (all NaN)"),
        ({"ACT_SET1_OUT": 7, "ACT_SET2_OUT": 4}, (1.0, 0.0) + (NAN,) * 4, 0,
         "ACT_SET2_OUT 4 drives the throttle"),
        ({"ACT_SET1_OUT": 7}, (1.0,) + (NAN,) * 5, 1, "index 1: only sets 1-6 (index 0) exist"),
    ],
)  # fmt: skip
def test_a_command_that_cannot_be_done_moves_nothing_and_says_why(params, values, index, reason):
    a, sent, said = actuators(**params)
    assert a.act(1, values, index) == f"Set actuator: {reason}"
    assert sent == [] and said == []  # the ack carries the reason to the ground station
