"""A payload gripper on a servo output (DO_GRIPPER), as an ArduPilot user drops a payload
and as QGroundControl's "Gripper Mechanism" item and MAVSDK's Gripper plug-in ask: grab and
release set GRIP_OUTPUT to GRIP_GRAB or GRIP_RELEASE for the servo output; a gripper not
set up, or on a surface's output, moves nothing and the operator is told why."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from companion.control.mission.gripper import GRIPPER_PARAMS, Gripper
from companion.control.mission.items import check_item, check_mission
from companion.messages import GRIPPER_SEQ, CommandId, VehicleCommand
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import HOME_ALT, executor, item, wp

SURFACES = {1: "aileron", 2: "elevator", 3: "rudder", 4: "throttle", 5: "flaps", 6: "brakes"}
DEFAULTS = {p.name: p.default for p in GRIPPER_PARAMS}


def grip(seq: int, action: float, which: float = 1.0):
    """As QGroundControl 4.4.5 saves "Gripper Mechanism": param1 the gripper (1), param2
    the action (0 release, 1 grab), frame MISSION, no place."""
    return replace(item(seq, d.MAV_CMD_DO_GRIPPER, p1=which, p2=action), frame=d.MAV_FRAME_MISSION)


def gripper(**params: float) -> tuple[Gripper, list[VehicleCommand], list[tuple[int, str]]]:
    sent: list[VehicleCommand] = []
    said: list[tuple[int, str]] = []
    g = Gripper(sent.append, lambda _t, severity, text: said.append((severity, text)), SURFACES)
    g.configure({**DEFAULTS, **params})
    return g, sent, said


def pulses(sent: list[VehicleCommand]) -> list[tuple[int, int, int]]:
    assert all(c.command == CommandId.SET_SERVO for c in sent)
    return [(c.seq, round(c.param[0]), round(c.param[1])) for c in sent]


def test_a_release_or_grab_is_accepted_at_upload_and_another_action_refused():
    assert check_item(grip(0, 0.0), 1) == d.MAV_MISSION_ACCEPTED
    assert check_item(grip(0, 1.0, which=math.nan), 1) == d.MAV_MISSION_ACCEPTED
    for action in (2.0, 0.5, -1.0, math.nan, math.inf):
        assert check_item(grip(0, action), 1) == d.MAV_MISSION_INVALID_PARAM2, action
    plan = [wp(0, (0.0, 1000.0)), grip(1, 0.0), wp(2, (1000.0, 1000.0))]
    assert check_mission(plan) == d.MAV_MISSION_ACCEPTED


def test_the_executor_hands_it_out_as_it_passes_and_flies_on_to_the_next_waypoint():
    release = grip(1, 0.0)
    ex = executor([wp(0, (0.0, 1000.0)), release, wp(2, (1000.0, 1000.0))])
    ex.step((0.0, 10.0), HOME_ALT + 100.0, 0.0)
    assert ex.take_actions() == ([], [])  # not before its waypoint
    sp = ex.step((0.0, 1000.0), HOME_ALT + 100.0, 1.0)
    assert sp.b == pytest.approx((1000.0, 1000.0), abs=0.01) and ex.current == 2
    assert ex.take_actions() == ([], [release])
    assert ex.take_actions() == ([], [])


def test_grab_and_release_set_the_output_to_their_pulses_and_say_so():
    g, sent, said = gripper(GRIP_ENABLE=1.0)
    assert g.act(10, 1) is None
    assert g.act(20, 0) is None
    assert pulses(sent) == [(GRIPPER_SEQ, 8, 1900), (GRIPPER_SEQ, 8, 1100)]
    assert said == [
        (d.MAV_SEVERITY_INFO, "Gripper: grab"),
        (d.MAV_SEVERITY_INFO, "Gripper: release"),
    ]
    g.configure({**DEFAULTS, "GRIP_ENABLE": 1.0, "GRIP_OUTPUT": 7.0, "GRIP_RELEASE": 1250.0})
    g.items(30, [item(1, d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, p1=40.0), grip(2, 0.0)])
    assert pulses(sent)[2:] == [(GRIPPER_SEQ, 7, 1250)]  # the camera's item is not its own


def test_a_gripper_not_set_up_or_on_a_surface_moves_nothing_and_says_why():
    g, sent, said = gripper()  # GRIP_ENABLE 0, as shipped
    assert g.act(10, 0) == "Gripper: not set up (GRIP_ENABLE is 0)"
    g.items(20, [grip(3, 0.0)])
    assert said == [(d.MAV_SEVERITY_WARNING, "Mission: Gripper: not set up (GRIP_ENABLE is 0)")]
    g.configure({**DEFAULTS, "GRIP_ENABLE": 1.0, "GRIP_OUTPUT": 2.0})
    assert g.act(30, 1) == "Gripper: GRIP_OUTPUT 2 drives the elevator"
    assert sent == []
