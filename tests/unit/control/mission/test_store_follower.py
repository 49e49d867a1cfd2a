"""mission/changed: a reader reloads the store only when the link's checksum differs."""

from __future__ import annotations

from companion.control.mission.mission_files import MissionStore, StoreFollower
from companion.control.mission.plan import load_plan
from tests.support.vehicle import REPO


def test_a_new_mission_is_followed_and_the_same_one_stored_again_is_not(tmp_path):
    square = load_plan(REPO / "qgc_plans" / "square.plan")[0]
    short = load_plan(REPO / "qgc_plans" / "short_leg.plan")[0]
    link = MissionStore(tmp_path)  # the link's copy: it stores uploads
    follower = StoreFollower(MissionStore(tmp_path))  # another process's copy
    assert follower.follow(link.changed(0, 1)) == set()  # both empty

    link.replace(0, square)
    assert follower.follow(link.changed(0, 2)) == {0}
    assert len(follower.store.items[0]) == len(square)

    link.replace(0, square)  # an identical upload: nothing to restart
    msg = link.changed(0, 3)
    assert (msg.count, msg.counts[0]) == (len(square), len(square))
    assert follower.follow(msg) == set()

    link.replace(0, short)
    assert follower.follow(link.changed(0, 4)) == {0}
    assert [(i.command, i.x, i.y) for i in follower.store.items[0]] == [
        (i.command, i.x, i.y) for i in short
    ]
    assert follower.follow(None) == set()
