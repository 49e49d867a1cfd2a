"""DO_SET_HOME in a mission, as QGroundControl's Plan view offers it to a PX4 plane and
ArduPlane flies it: param1 1 makes the aircraft's place home, 0 the item's. Passed on the
way like any DO item (the next waypoint flown at once), it becomes the commander's
SET_HOME; a place or an action it cannot be is refused at upload."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from companion.control.mission.home_items import set_home_command
from companion.control.mission.items import check_item
from companion.messages import (
    MISSION_HOME_SEQ,
    CommandId,
)
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import HOME, HOME_ALT, cruising, executor, item, wp

PLACE = (1500.0, -500.0)  # metres north and east of home


def home_item(seq: int, use_here: float, ne=PLACE, z: float = 20.0):
    """As QGroundControl saves it: a place (relative altitude) with param1 0, none with 1."""
    return item(seq, d.MAV_CMD_DO_SET_HOME, ne if use_here == 0 else None, z, p1=use_here)


def test_a_place_or_here_is_accepted_and_nonsense_refused_at_upload():
    assert check_item(home_item(0, 0.0), 1) == d.MAV_MISSION_ACCEPTED
    here = replace(home_item(0, 1.0), frame=d.MAV_FRAME_MISSION)
    assert check_item(here, 1) == d.MAV_MISSION_ACCEPTED
    assert check_item(home_item(0, 0.0, ne=None), 1) == d.MAV_MISSION_INVALID_PARAM5_X
    for bad in (2.0, 0.5, -1.0, math.nan):
        assert check_item(home_item(0, bad), 1) == d.MAV_MISSION_INVALID_PARAM1, bad
    assert check_item(home_item(0, 0.0, z=math.nan), 1) == d.MAV_MISSION_INVALID_PARAM7


def test_the_executor_hands_it_out_as_it_passes_and_flies_on():
    new_home = home_item(1, 0.0)
    ex = executor([wp(0, (0.0, 1000.0)), new_home, wp(2, (1000.0, 1000.0))])
    ex.step((0.0, 10.0), HOME_ALT + 100.0, 0.0)
    assert ex.take_actions() == ([], [])
    sp = ex.step((0.0, 1000.0), HOME_ALT + 100.0, 1.0)
    assert sp.b == pytest.approx((1000.0, 1000.0), abs=0.01)  # not flown to its place
    assert ex.take_actions() == ([], [new_home]) and ex.current == 2


def test_it_becomes_the_commanders_set_home_with_its_altitude_above_sea_level():
    cmd = set_home_command(home_item(3, 0.0), 7, HOME_ALT)
    assert (cmd.command, cmd.seq, cmd.t_us) == (int(CommandId.SET_HOME), MISSION_HOME_SEQ, 7)
    lat, lon = HOME.latlon(*PLACE)
    assert cmd.param[0] == 0.0
    assert list(cmd.param[4:7]) == pytest.approx([lat, lon, HOME_ALT + 20.0], abs=1e-7)
    msl = replace(home_item(3, 0.0), frame=d.MAV_FRAME_GLOBAL_INT)
    assert set_home_command(msl, 7, HOME_ALT).param[6] == 20.0
    here = set_home_command(home_item(4, 1.0), 8, HOME_ALT)
    assert here.param[0] == 1.0  # the commander takes the aircraft's place


def test_home_moved_here_in_the_air_the_mission_goes_on_and_is_not_set_again():
    """Param1 1 in the air: the controller takes home from the commander's next status and
    its frame moves. The mission is taken up at the item after DO_SET_HOME, not at the
    one the commander last heard of (the item itself: home set here once more, a little
    further on each time, for ever)."""
    here = replace(home_item(1, 1.0), frame=d.MAV_FRAME_MISSION)
    controller, nav, status = cruising(
        [wp(0, (0.0, 30.0)), here, wp(2, (0.0, 2000.0)), wp(3, (2000.0, 2000.0))]
    )
    passed = [controller.step(nav, status, k * 0.02).passed_items for k in range(5)]
    assert [p for p in passed if p] == [[here]]
    # The commander took it (home is where the aircraft was) and still says item 1.
    status.home_lat_deg, status.home_lon_deg = nav.lat_deg, nav.lon_deg
    status.home_alt_msl_m, status.mission_first = nav.alt_msl_m, 1
    later = [controller.step(nav, status, 0.1 + k * 0.02) for k in range(5)]
    assert [o.passed_items for o in later if o.passed_items] == []
    assert later[-1].mission_seq == 2
