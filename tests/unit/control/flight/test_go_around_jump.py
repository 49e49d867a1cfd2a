"""A go-around comes round to the landing's approach, not to the DO_JUMP loop flown before.

A plan made in QGroundControl without its landing pattern: a loop of waypoints, flown
twice by a DO_JUMP, then NAV_LAND straight after the jump (or after the approach waypoint
with the jump between the two). A go-around flies the approach again from the positional
item before NAV_LAND (``approach_start``); the DO_JUMP on the way from there has done its
repeats and must send the aircraft on to the landing, not round the loop again.
"""

from __future__ import annotations

import pytest

from companion.control.flight.landing_flight import LandingFlight, approach_start
from companion.control.mission.executor import Kind
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import (
    HOME_ALT,
    executor,
    fly_lines,
    item,
    jump,
    wp,
)

LAND = (0.0, 3_000.0)


def _loop_then_land(jump_after_approach: bool) -> list:
    loop = [wp(0, (0.0, 1_000.0)), wp(1, (1_000.0, 1_000.0)), wp(2, (0.0, 0.0))]
    approach = wp(3, (0.0, 1_500.0))
    tail = [approach, jump(4, 0, 1)] if jump_after_approach else [jump(3, 0, 1)]
    land = item(len(loop) + len(tail), d.MAV_CMD_NAV_LAND, LAND, z=0.0)
    return [*loop, *tail, land]


@pytest.mark.parametrize("jump_after_approach", [False, True])
def test_a_go_around_after_the_loop_comes_round_to_the_landing(jump_after_approach: bool):
    items = _loop_then_land(jump_after_approach)
    ex = executor(items)
    reached, setpoints, pos = fly_lines(ex)
    assert setpoints[-1].kind == Kind.LAND
    laps = [0, 1, 2, 3] if jump_after_approach else [0, 1, 2]
    assert reached == laps + laps  # the loop flown twice, then the final
    lander = LandingFlight(None, None)  # type: ignore[arg-type]  # only its mission part
    lander._come_round(ex, pos, HOME_ALT + 100.0)  # climbed out after the go-around
    again, setpoints, _ = fly_lines(ex, pos)
    assert setpoints[-1].kind == Kind.LAND  # the second approach ...
    assert again == [items[-3].seq]  # ... from its start, on to the landing


def test_a_go_around_comes_round_to_the_last_waypoint_not_a_region_of_interest():
    """A region of interest set between the approach's waypoint and NAV_LAND has a place of
    its own, 2 km off to the side; the second approach begins at the waypoint."""
    items = [
        wp(0, (0.0, 1_500.0)),
        item(1, d.MAV_CMD_DO_SET_ROI_LOCATION, (2_000.0, 2_000.0), z=10.0),
        item(2, d.MAV_CMD_NAV_LAND, LAND, z=0.0),
    ]
    assert approach_start(items, 2) == 0
