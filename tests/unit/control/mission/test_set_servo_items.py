"""DO_SET_SERVO in a mission, as an ArduPilot user drops a payload: passed on the way like
DO_CHANGE_SPEED, it is handed out once (``servo_sets``) and the next waypoint flown; an
output the card does not have, or a pulse it cannot put out, is refused at upload."""

from __future__ import annotations

import math

import pytest

from companion.control.mission.executor import Kind
from companion.control.mission.items import check_item
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import HOME_ALT, cruising, executor, item, wp


def servo(seq: int, output: float, pulse: float):
    return item(seq, d.MAV_CMD_DO_SET_SERVO, p1=output, p2=pulse)


def test_an_output_or_pulse_the_card_lacks_is_refused_at_upload():
    assert check_item(servo(0, 7, 1900), 1) == d.MAV_MISSION_ACCEPTED
    for output in (0, 9, 2.5, math.nan):
        assert check_item(servo(0, output, 1900), 1) == d.MAV_MISSION_INVALID_PARAM1, output
    for pulse in (999, 2001, 1500.5, math.nan):
        assert check_item(servo(0, 7, pulse), 1) == d.MAV_MISSION_INVALID_PARAM2, pulse


def test_the_executor_hands_it_out_once_as_it_passes_and_flies_on():
    items = [wp(0, (0.0, 1000.0)), servo(1, 7, 1900), servo(2, 8, 1100), wp(3, (1000.0, 1000.0))]
    ex = executor(items)
    sp = ex.step((0.0, 10.0), HOME_ALT + 100.0, 0.0)
    assert sp.b == pytest.approx((0.0, 1000.0), abs=0.01)
    assert ex.servo_sets == []  # not before its waypoint is reached
    sp = ex.step((0.0, 1000.0), HOME_ALT + 100.0, 1.0)
    assert sp.kind == Kind.LINE and sp.b == pytest.approx((1000.0, 1000.0), abs=0.01)
    assert ex.servo_sets == [(7, 1900), (8, 1100)] and ex.current == 3


def test_the_controller_says_it_in_one_step_only():
    controller, nav, status = cruising(
        [wp(0, (0.0, 30.0)), servo(1, 7, 1900), wp(2, (0.0, 2000.0))]
    )
    said = [controller.step(nav, status, k * 0.02).servo_sets for k in range(5)]
    assert [s for s in said if s] == [[(7, 1900)]]
