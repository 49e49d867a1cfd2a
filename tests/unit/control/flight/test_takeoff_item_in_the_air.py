"""A take-off item flown in the air (a DO_JUMP back to it) climbs, and is no runway.

Land without a landing in the mission comes back onto the runway of this flight's take-off
(``LandingFlight._home_landing``). A plan whose DO_JUMP returns to its NAV_TAKEOFF below
the take-off's height flies that item in the air: it climbs on the heading it has, and
that heading and place were taken for the runway, so a Land after it would have laid its
pattern along whatever way the aircraft happened to fly at the jump.
"""

from __future__ import annotations

from mavlink_dialect import companion as d
from tests.support.closed_loop import ClosedLoop
from tests.unit.control.mission.executor_flying import item, wp

ITEMS = [item(0, d.MAV_CMD_NAV_TAKEOFF, (0.0, 600.0), z=100.0, p1=15.0), wp(1, (3_000.0, 0.0))]


def test_a_take_off_item_met_in_the_air_climbs_to_its_height_and_is_no_runway():
    loop = ClosedLoop("c172p", ITEMS, airborne_agl_m=60.0)
    loop.run(1.0)
    assert loop.controller.takeoff is not None  # flying the take-off item: climbing
    assert loop.controller.lander.runway is None
    loop.run(60.0)
    assert loop.reached[:1] == [0] and loop.samples[-1].alt_agl > 90.0
    assert loop.samples[-1].out.mission_seq == 1  # then on to the waypoint
    assert loop.controller.lander.runway is None


def test_the_take_off_roll_is_the_runway():
    loop = ClosedLoop("c172p", ITEMS)
    loop.run(5.0)
    runway = loop.controller.lander.runway
    assert runway is not None and runway is loop.controller.takeoff
