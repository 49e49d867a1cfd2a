"""The mission executor's loiters and delays, RTL, the end of the mission and starting part way.

As in test_executor.py: the aircraft is teleported and the executor stepped at each point.
"""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from companion.control.mission.executor import ExecutorConfig, Kind, MissionExecutor
from companion.control.mission.items import check_mission
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import (
    HOME,
    HOME_ALT,
    dist,
    executor,
    fly_lines,
    item,
    jump,
    on_circle,
    towards,
    wp,
)

# --- loiters -------------------------------------------------------------------------------


def test_loiter_time_counts_from_reaching_the_circle():
    centre, radius = (1_000.0, 0.0), 100.0
    items = [item(0, d.MAV_CMD_NAV_LOITER_TIME, centre, z=100.0, p1=30.0, p3=radius)]
    ex = executor(items)
    for t in range(0, 100, 5):  # a long way off: time does not count
        sp = ex.step((0.0, 0.0), 180.0, float(t))
        assert sp.kind == Kind.CIRCLE and not ex.finished
    assert sp.b == pytest.approx(centre, abs=0.05) and sp.radius == radius and sp.clockwise
    assert sp.alt_msl == pytest.approx(HOME_ALT + 100.0)
    # On the circle from t = 100: done at t = 130, not before.
    t = 100.0
    while t < 129.9:
        ex.step(on_circle(centre, radius, 6.0 * (t - 100.0)), 180.0, t)
        assert ex.drain_reached() == [] and not ex.finished, t
        t += 0.5
    sp = ex.step(on_circle(centre, radius, 180.0), 180.0, 130.0)
    assert ex.drain_reached() == [0]
    assert ex.finished and sp.kind == Kind.CIRCLE  # the last item: circles its point
    assert sp.b == pytest.approx(centre, abs=0.05)


def test_loiter_time_starts_counting_within_a_quarter_radius_of_the_circle():
    centre, radius = (1_000.0, 0.0), 100.0
    items = [item(0, d.MAV_CMD_NAV_LOITER_TIME, centre, z=100.0, p1=10.0, p3=radius)]
    ex = executor(items)
    ex.step((870.0, 0.0), 180.0, 0.0)  # 130 m from the centre: not yet on the circle
    ex.step((880.0, 0.0), 180.0, 5.0)  # 120 m: on it
    ex.step((880.0, 0.0), 180.0, 14.9)
    assert not ex.finished
    ex.step((880.0, 0.0), 180.0, 15.0)
    assert ex.finished and ex.drain_reached() == [0]


def test_a_delay_circles_the_last_waypoint_at_its_height_for_its_seconds_from_its_start():
    """NAV_DELAY as QGroundControl sends it (no place, no height, the time-of-day fields -1)
    holds the aircraft round the waypoint before it, counted from its start as PX4 and
    ArduPlane count it, then the mission goes on from that waypoint."""
    a, b = (500.0, 0.0), (1_500.0, 0.0)
    delay = item(1, d.MAV_CMD_NAV_DELAY, p1=30.0, p2=-1.0, p3=-1.0)
    delay = replace(delay, frame=d.MAV_FRAME_MISSION)
    ex = executor([wp(0, a, z=120.0), delay, wp(2, b, z=120.0)])
    reached, setpoints, pos = fly_lines(ex)  # to the waypoint; the delay began there
    assert reached == [0]
    began = float(len(setpoints) - 1)  # fly_lines steps once a second
    for t in range(1, 30):  # from the waypoint out to the circle and round: not done
        sp = ex.step(towards(pos, (500.0, 200.0), 6.0 * t), HOME_ALT + 120.0, began + t)
        assert sp.kind == Kind.CIRCLE and ex.drain_reached() == [], t
        assert sp.b == pytest.approx(a, abs=0.05) and sp.alt_msl == HOME_ALT + 120.0
        assert sp.radius == ExecutorConfig().loiter_radius and sp.clockwise
    sp = ex.step((500.0, 80.0), HOME_ALT + 120.0, began + 30.0)
    assert ex.drain_reached() == [1]
    assert (
        sp.kind == Kind.LINE
        and sp.a == pytest.approx(a, abs=0.05)
        and sp.b == pytest.approx(b, abs=0.05)
    )


def test_a_delay_until_a_time_of_day_is_refused_at_upload():
    ok = replace(item(1, d.MAV_CMD_NAV_DELAY, p1=30.0), frame=d.MAV_FRAME_MISSION)
    assert check_mission([wp(0, (500.0, 0.0)), ok]) == d.MAV_MISSION_ACCEPTED
    for p1 in (-1.0, math.nan):
        bad = replace(ok, param1=p1, param2=12.0)
        assert check_mission([wp(0, (500.0, 0.0)), bad]) == d.MAV_MISSION_INVALID_PARAM1


@pytest.mark.parametrize("direction", [+1, -1])
def test_loiter_turns_completes_after_720_degrees(direction: int):
    centre, radius = (1_000.0, 0.0), 100.0
    items = [
        item(0, d.MAV_CMD_NAV_LOITER_TURNS, centre, z=100.0, p1=2.0, p3=radius),
        wp(1, (2_000.0, 0.0)),
    ]
    ex = executor(items)
    assert ex.step((0.0, 0.0), 180.0, 0.0).kind == Kind.CIRCLE
    done_at = None
    for k in range(800):  # one degree per step, from 180° round the circle
        sp = ex.step(on_circle(centre, radius, 180.0 + direction * k), 180.0, 1.0 + k)
        if ex.drain_reached() == [0]:
            done_at = k
            break
        assert sp.kind == Kind.CIRCLE
    assert done_at is not None
    assert 700 <= done_at <= 722
    assert sp.kind == Kind.LINE and sp.b == pytest.approx((2_000.0, 0.0), abs=0.05)
    assert sp.a == pytest.approx(centre, abs=0.05)  # the next leg starts at its centre


@pytest.mark.parametrize("command", [d.MAV_CMD_NAV_LOITER_TIME, d.MAV_CMD_NAV_LOITER_TURNS])
@pytest.mark.parametrize("p3", [0.0, 75.0, -75.0])
def test_a_loiter_tighter_than_the_aircraft_turns_ends_on_the_circle_it_flies(
    command: int, p3: float
):
    """The controller flies a circle tighter than its turn at its turn radius (a C172 at
    cruise: 216 m); the loiter counts its time and turns on that circle. Judged on the
    plan's 75 m (or the 80 m default) it never began: the mission circled there forever."""
    centre, flown = (1_000.0, 0.0), 216.0
    items = [item(0, command, centre, z=100.0, p1=1.0, p3=p3), wp(1, (3_000.0, 0.0))]
    ex = executor(items)
    way = -1.0 if p3 < 0 else 1.0
    for k in range(400):  # two degrees a second round the circle it flies
        sp = ex.step(on_circle(centre, flown, 180.0 + way * 2.0 * k), 180.0, float(k), flown)
        if ex.drain_reached() == [0]:
            break
    assert sp.kind == Kind.LINE and sp.b == pytest.approx((3_000.0, 0.0), abs=0.05), k
    assert k <= 181  # one turn, or a second on it


def test_a_waypoint_where_the_loiter_before_it_circled_is_flown_to_and_passed():
    """A loiter at a waypoint's place, then a DO_JUMP back to that waypoint (or the
    waypoint after the loiter): the leg to it began at the loiter's centre, the waypoint
    itself, and a leg from a point to itself has no finish line. The aircraft, still on its
    216 m circle, never came within 30 m of the point: a whole vehicle circled there until
    its battery ran low. The leg now starts where the aircraft is; circling on, the
    waypoint is passed once the aircraft is beyond it."""
    p, flown = (1_000.0, 0.0), 216.0
    items = [wp(0, p), wp(1, (0.0, 1_500.0)),
             item(2, d.MAV_CMD_NAV_LOITER_TIME, p, z=100.0, p1=10.0),
             jump(3, 0, 1), wp(4, (-1_500.0, 0.0))]  # fmt: skip
    ex = executor(items)
    reached, setpoints, _ = fly_lines(ex, turn_radius=flown)
    assert reached == [0, 1] and setpoints[-1].kind == Kind.CIRCLE
    for k in range(360):  # on round the circle it flies, two degrees a second
        sp = ex.step(on_circle(p, flown, 90.0 + 2.0 * k), 180.0, 100.0 + k, flown)
        reached += ex.drain_reached()
        if reached[2:] == [2, 0]:
            break
    assert reached == [0, 1, 2, 0], reached  # the loiter, then the waypoint it circled
    assert sp.kind == Kind.LINE and sp.b == pytest.approx((0.0, 1_500.0), abs=0.05)


@pytest.mark.parametrize(
    "command",
    [d.MAV_CMD_NAV_LOITER_UNLIM, d.MAV_CMD_NAV_LOITER_TIME, d.MAV_CMD_NAV_LOITER_TURNS],
)
@pytest.mark.parametrize(
    ("p3", "radius", "clockwise"), [(150.0, 150.0, True), (-150.0, 150.0, False), (0.0, 80.0, True)]
)
def test_loiter_radius_sign_gives_the_direction(
    command: int, p3: float, radius: float, clockwise: bool
):
    ex = executor([item(0, command, (1_000.0, 0.0), z=100.0, p1=5.0, p3=p3)])
    sp = ex.step((0.0, 0.0), 180.0, 0.0)
    assert sp.kind == Kind.CIRCLE
    assert sp.radius == radius  # 0: the configured default
    assert sp.clockwise is clockwise


def test_loiter_unlimited_never_ends():
    centre = (1_000.0, 0.0)
    ex = executor([item(0, d.MAV_CMD_NAV_LOITER_UNLIM, centre, z=100.0, p3=80.0)])
    for k in range(2_000):
        sp = ex.step(on_circle(centre, 80.0, 2.0 * k), 180.0, float(k))
    assert sp.kind == Kind.CIRCLE and not ex.finished and ex.drain_reached() == []


# --- RTL and the end of the mission ---------------------------------------------------------


def test_rtl_ends_the_mission_as_it_begins_then_flies_home_at_rtl_altitude_and_circles():
    """The item is reached, and the mission finished, as it is begun: the commander enters
    Return on it. Flown without Return, home at the return height, then circled."""
    config = ExecutorConfig(rtl_alt_rel=60.0, loiter_radius=80.0)
    items = [wp(0, (1_500.0, 0.0), z=120.0), item(1, d.MAV_CMD_NAV_RETURN_TO_LAUNCH)]
    ex = executor(items, config=config)
    reached, setpoints, pos = fly_lines(ex, step_m=10.0)
    assert reached == [0, 1] and ex.finished
    assert dist(pos, (1_500.0, 0.0)) < 50.0  # at the last waypoint, not home
    final, home_legs = setpoints[-1], []
    for t in range(1_000):
        if final.kind != Kind.LINE:
            break
        home_legs.append(final)
        pos = towards(pos, final.b, 10.0)
        final = ex.step(pos, final.alt_msl, 1e3 + t)
        assert ex.drain_reached() == []  # reached once, as it began
    assert home_legs
    for sp in home_legs:
        assert sp.b == (0.0, 0.0)
        assert sp.a == pytest.approx((1_500.0, 0.0), abs=0.05)  # from the last waypoint
        assert sp.alt_msl == pytest.approx(HOME_ALT + 60.0)
        assert not math.isfinite(sp.speed)
    assert final.kind == Kind.CIRCLE
    assert final.b == (0.0, 0.0) and final.radius == 80.0
    assert final.alt_msl == pytest.approx(HOME_ALT + 60.0)
    assert dist(pos, (0.0, 0.0)) <= 120.0  # switched once within 1.5 loiter radii
    assert dist(pos, (0.0, 0.0)) > 100.0  # ... and not before
    # Circling home from now on, reported reached only once.
    for t in range(50):
        sp = ex.step(on_circle((0.0, 0.0), 80.0, 7.0 * t), 140.0, 1e4 + t)
        assert sp.kind == Kind.CIRCLE and sp.b == (0.0, 0.0)
        assert ex.drain_reached() == []


def test_after_the_last_item_it_circles_the_last_point():
    items = [wp(0, (500.0, 0.0), z=50.0), wp(1, (500.0, 500.0), z=70.0)]
    ex = executor(items)
    ex.step((0.0, 0.0), 180.0, 0.0)
    ex.step((490.0, 0.0), 180.0, 1.0)
    assert ex.drain_reached() == [0] and not ex.finished
    sp = ex.step((500.0, 480.0), 150.0, 2.0)  # 20 m short: within the acceptance radius
    assert ex.drain_reached() == [1]
    assert ex.finished
    assert sp.kind == Kind.CIRCLE
    assert sp.b == pytest.approx((500.0, 500.0), abs=0.05)  # the waypoint, not the aircraft
    assert sp.radius == ExecutorConfig().loiter_radius
    assert sp.alt_msl == pytest.approx(HOME_ALT + 70.0)
    # The aircraft moving about does not move the circle.
    for t in range(3, 20):
        again = ex.step((500.0 + 10 * t, 500.0), 150.0, float(t))
        assert again == sp and ex.finished


def test_start_part_way_through_skips_the_earlier_items():
    items = [wp(0, (500.0, 0.0)), wp(1, (500.0, 500.0)), wp(2, (0.0, 500.0))]
    ex = MissionExecutor(items, HOME, HOME_ALT)
    ex.start(1, (100.0, 100.0), 180.0)
    sp = ex.step((100.0, 100.0), 180.0, 0.0)
    assert sp.a == (100.0, 100.0)  # from where the aircraft is
    assert sp.b == pytest.approx((500.0, 500.0), abs=0.05)
