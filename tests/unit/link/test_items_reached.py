"""MISSION_ITEM_REACHED for every item the controller reached, not only the last of a step.

A loiter that ends where a DO_JUMP sends the mission back to its take-off item (done at
once: the aircraft is above its height) reaches both in one step; the ground station was
told only of the take-off, and a mission's log of reached items missed the loiter on
every lap. The controller's status keeps its last few reached items, the link tells each.
"""

from __future__ import annotations

from pymavlink.dialects.v20 import common as m

from companion.link.flight_messages import mission_items_reached
from companion.messages import ControlStatus

MAV = m.MAVLink(None)


def _status(reached: list[int]) -> ControlStatus:
    """As control.fixed_wing fills it after reaching ``reached``, in order."""
    s = ControlStatus(reached_count=len(reached), last_reached=reached[-1] if reached else -1)
    for n, seq in enumerate(reached):
        s.recent_reached[n % ControlStatus.REACHED_KEPT] = seq
    return s


def _told(reached: list[int], told: int) -> list[int]:
    return [msg.seq for msg in mission_items_reached(MAV, _status(reached), told)]


def test_two_items_reached_in_one_step_are_both_told():
    assert _told([0, 1, 2, 3, 4, 0], told=4) == [4, 0]


def test_nothing_new_nothing_told():
    assert _told([0, 1, 2], told=3) == []
    assert _told([], told=0) == []
    assert _told([], told=-1) == []


def test_a_link_that_starts_late_tells_only_the_last():
    assert _told([0, 1, 2], told=-1) == [2]


def test_a_restarted_controller_counting_from_zero_is_told_from_its_first():
    assert _told([3], told=7) == [3]
    assert _told([3, 1], told=7) == [3, 1]


def test_more_than_it_keeps_tells_the_newest_it_keeps():
    reached = list(range(20))
    told = _told(reached, told=2)
    assert told == reached[-ControlStatus.REACHED_KEPT :]
