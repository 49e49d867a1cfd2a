"""The mission executor: which item is current, what setpoint it gives, and when items end.

No dynamics: the aircraft is teleported along the path (or round a circle) and the
executor is stepped at each position, so what is tested is only the executor's logic —
take-off, waypoint acceptance (radius, the square line, the turn lead), DO_CHANGE_SPEED,
DO_JUMP, items for what the vehicle does not carry, the loiters, RTL and what happens after
the last item.
"""

from __future__ import annotations

import math

import pytest

from companion.control.mission.executor import Kind
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import (
    HOME_ALT,
    dist,
    executor,
    fly_lines,
    item,
    jump,
    speed,
    towards,
    wp,
)


def test_takeoff_climbs_until_within_5_m_then_flies_on():
    items = [item(0, d.MAV_CMD_NAV_TAKEOFF, None, z=50.0), wp(1, (1_000.0, 0.0))]
    ex = executor(items, alt=HOME_ALT)
    for k, alt in enumerate([80.0, 100.0, 120.0, 124.9]):
        pos = (k * 20.0, 0.0)
        sp = ex.step(pos, alt, float(k))
        assert sp.kind == Kind.TAKEOFF
        assert sp.alt_msl == pytest.approx(HOME_ALT + 50.0)  # relative to home
        assert ex.current == 0 and not ex.finished
        assert ex.drain_reached() == []
    pos = (100.0, 0.0)
    sp = ex.step(pos, 125.1, 5.0)
    assert ex.drain_reached() == [0]
    assert sp.kind == Kind.LINE
    assert sp.a == (100.0, 0.0)  # the leg starts where the climb ended (ArduPlane)
    assert sp.b == pytest.approx((1_000.0, 0.0), abs=0.05)
    assert sp.alt_msl == pytest.approx(HOME_ALT + 100.0)


def climb_ending_at(end, second, turn_radius=150.0):
    """A take-off to 100 m east along the runway, waypoints at (0, 900) and ``second``; the
    executor and its setpoint when the climb ends at ``end``."""
    items = [item(0, d.MAV_CMD_NAV_TAKEOFF, None, z=100.0), wp(1, (0.0, 900.0)), wp(2, second)]
    ex = executor(items, alt=HOME_ALT)
    ex.step((0.0, 0.0), HOME_ALT, 0.0, turn_radius=turn_radius)
    return ex, ex.step(end, HOME_ALT + 99.0, 40.0, turn_radius=turn_radius)


def test_a_waypoint_the_climb_flew_past_is_flown_back_to():
    """A take-off with the wind behind it ended 700 m beyond the J3Cub's first waypoint:
    met 1 km down the next leg, that leg was flown 400 m off its line. Past the waypoint
    and off the next leg by more than the acceptance radius, the aircraft now turns back
    and flies the waypoint, from which the next leg starts on its line."""
    ex, sp = climb_ending_at((0.0, 1_200.0), (1_500.0, 2_400.0))
    assert ex.drain_reached() == [0]
    assert sp.kind == Kind.LINE
    assert sp.a == pytest.approx((0.0, 1_200.0), abs=0.05)  # from here, back to it
    assert sp.b == pytest.approx((0.0, 900.0), abs=0.05)
    sp = ex.step((0.0, 1_200.0), HOME_ALT + 100.0, 41.0, turn_radius=150.0)
    assert ex.drain_reached() == [] and sp.b == pytest.approx((0.0, 900.0), abs=0.05)


def test_a_climb_that_ends_within_a_turn_radius_of_the_first_waypoint_has_passed_it():
    """The c172p's zigzag climb ended 30 m beside its first waypoint: a leg from there back
    to it made the aircraft swing 270 m round it. Within a turn radius (150 m here) of it,
    past it or not, it counts as reached and the next leg starts at it."""
    for end in ((40.0, 920.0), (0.0, 1_040.0)):
        ex, sp = climb_ending_at(end, (1_500.0, 2_400.0))
        assert ex.drain_reached() == [0, 1]
        assert sp.a == pytest.approx((0.0, 900.0), abs=0.05)
        assert sp.b == pytest.approx((1_500.0, 2_400.0), abs=0.05)


def test_a_waypoint_the_climb_flew_past_on_the_next_legs_line_is_flown_back_to():
    """Issue 42.7: climbing east along the runway, the take-off ends 500 m beyond the first
    waypoint, on the line of the next leg (straight on east). The leg to it used to start
    at the take-off item, so the aircraft counted it as passed and joined the next leg
    500 m beyond it; from where the climb ended (ArduPlane) it is flown back to."""
    ex, sp = climb_ending_at((0.0, 1_400.0), (0.0, 2_400.0))
    assert ex.drain_reached() == [0]
    assert sp.kind == Kind.LINE
    assert sp.a == pytest.approx((0.0, 1_400.0), abs=0.05)
    assert sp.b == pytest.approx((0.0, 900.0), abs=0.05)
    # Turning back towards it, still 300 m off, then 100 m short on its line: not reached
    # (the lead before the reversal onto the next leg, 250 m here, does not count).
    for k, pos in enumerate([(-150.0, 1_200.0), (0.0, 1_000.0)]):
        sp = ex.step(pos, HOME_ALT + 100.0, 60.0 + k, turn_radius=150.0)
        assert ex.drain_reached() == [] and sp.b == pytest.approx((0.0, 900.0), abs=0.05)
    # Passed within the acceptance radius: reached, and the next leg starts at it.
    sp = ex.step((0.0, 880.0), HOME_ALT + 100.0, 80.0)
    assert ex.drain_reached() == [1]
    assert sp.a == pytest.approx((0.0, 900.0), abs=0.05)
    assert sp.b == pytest.approx((0.0, 2_400.0), abs=0.05)
    # Not yet at the waypoint when the climb ends: it is flown to, as before.
    ex, sp = climb_ending_at((0.0, 600.0), (0.0, 2_400.0), turn_radius=0.0)
    assert ex.drain_reached() == [0]
    assert sp.b == pytest.approx((0.0, 900.0), abs=0.05)


def test_an_implicit_take_off_climbs_ahead_then_flies_the_first_waypoint():
    """Issue 47.1: a mission without a take-off item, started on the ground (MAVSDK's
    mission.py): told to take off first, the executor climbs along the runway, then
    flies the first waypoint from where the climb ended."""
    items = [speed(0, 25.0), wp(1, (0.0, 900.0), z=60.0), wp(2, (900.0, 900.0), z=60.0)]
    ex = executor(items, alt=HOME_ALT)
    ex.take_off_first(HOME_ALT + 60.0)
    for k, alt in enumerate([HOME_ALT, HOME_ALT + 20.0, HOME_ALT + 54.0]):
        sp = ex.step((0.0, 300.0 * k), alt, float(k))
        assert sp.kind == Kind.TAKEOFF and sp.alt_msl == pytest.approx(HOME_ALT + 60.0)
        assert ex.current == 0 and ex.drain_reached() == []
    # Climbed (within 5 m) 1.2 km down the runway, past the first waypoint: flown back to.
    sp = ex.step((0.0, 1_200.0), HOME_ALT + 56.0, 5.0)
    assert ex.drain_reached() == []  # the waypoint is not counted as passed
    assert sp.kind == Kind.LINE and ex.current == 1 and ex.speed == 25.0
    assert sp.a == pytest.approx((0.0, 1_200.0), abs=0.05)
    assert sp.b == pytest.approx((0.0, 900.0), abs=0.05)


# --- waypoints -----------------------------------------------------------------------------


def test_waypoints_are_reached_in_order_and_reported_once():
    points = [(0.0, 800.0), (800.0, 800.0), (800.0, 0.0), (400.0, -300.0)]
    items = [wp(i, p, z=100.0 + 10 * i) for i, p in enumerate(points)]
    ex = executor(items)
    reached, setpoints, _ = fly_lines(ex)
    assert reached == [0, 1, 2, 3]
    assert ex.finished
    # Each leg went to its own waypoint, from the previous one, at that waypoint's height.
    legs = [sp for sp in setpoints if sp.kind == Kind.LINE]
    targets: list[tuple[float, float]] = []
    for sp in legs:
        if not targets or sp.b != targets[-1]:
            targets.append(sp.b)
    assert [pytest.approx(p, abs=0.05) for p in points] == targets
    starts = [(0.0, 0.0), *points[:-1]]  # the first leg from where the mission started
    for sp in legs:
        k = targets.index(sp.b)
        assert sp.alt_msl == pytest.approx(HOME_ALT + 100.0 + 10 * k)
        assert sp.a == pytest.approx(starts[k], abs=0.05)
    assert ex.drain_reached() == []  # already drained


def test_waypoint_acceptance_radius_from_the_item_or_the_default():
    ex = executor([wp(0, (1_000.0, 0.0), radius=100.0), wp(1, (1_000.0, 1_000.0))])
    assert ex.step((895.0, 0.0), 180.0, 0.0).b == pytest.approx((1_000.0, 0.0), abs=0.05)
    ex.step((905.0, 0.0), 180.0, 1.0)
    assert ex.drain_reached() == [0]
    # The next one takes the configured default (30 m).
    ex.step((1_000.0, 965.0), 180.0, 2.0)
    assert ex.drain_reached() == []
    ex.step((1_000.0, 975.0), 180.0, 3.0)
    assert ex.drain_reached() == [1]


def test_passing_the_square_line_reaches_a_waypoint_far_off_to_the_side():
    ex = executor([wp(0, (1_000.0, 0.0)), wp(1, (1_000.0, 1_000.0))])
    # 400 m to the side, just short of the line square to the leg: not yet.
    sp = ex.step((999.0, 400.0), 180.0, 0.0)
    assert ex.drain_reached() == [] and sp.b == pytest.approx((1_000.0, 0.0), abs=0.05)
    # Just past it: reached, though never inside its radius.
    sp = ex.step((1_001.0, 400.0), 180.0, 1.0)
    assert ex.drain_reached() == [0]
    assert sp.kind == Kind.LINE
    assert sp.a == pytest.approx((1_000.0, 0.0), abs=0.05)  # the next leg starts at it
    assert sp.b == pytest.approx((1_000.0, 1_000.0), abs=0.05)


def test_square_line_follows_the_leg_direction():
    # A leg flown south-west: "past" means further along the leg, not just further south.
    ex = executor([wp(0, (-1_000.0, -1_000.0)), wp(1, (-2_000.0, 0.0))])
    ex.step((-800.0, -1_100.0), 180.0, 0.0)  # beside it, still short
    ex.step((-1_150.0, -800.0), 180.0, 0.5)  # south of it, but still short along the leg
    assert ex.drain_reached() == []
    ex.step((-1_150.0, -1_000.0), 180.0, 1.0)  # past it, 150 m away
    assert ex.drain_reached() == [0]


def switch_distance(turn_radius: float, second: tuple[float, float] | None) -> float:
    """Fly north along the first leg in 1 m steps; how far from the corner it was reached."""
    corner = (1_000.0, 0.0)
    items = [wp(0, corner)] + ([wp(1, second)] if second else [])
    ex = executor(items)
    for k in range(1_001):
        pos = (float(k), 0.0)
        ex.step(pos, 180.0, float(k), turn_radius)
        if ex.drain_reached():
            return dist(pos, corner)
    raise AssertionError("the corner was never reached")


def test_turn_lead_switches_a_90_degree_corner_early():
    plain = switch_distance(0.0, (1_000.0, 1_000.0))
    lead = switch_distance(150.0, (1_000.0, 1_000.0))
    assert plain == pytest.approx(30.0, abs=1.0)  # the acceptance radius
    assert lead == pytest.approx(150.0, abs=1.0)  # R·tan(90°/2)


def test_turn_lead_is_smaller_for_a_gentle_turn_and_capped_by_the_legs():
    gentle = switch_distance(150.0, (2_000.0, 600.0))  # about 31° of turn
    turn = math.atan2(600.0, 1_000.0)
    assert gentle == pytest.approx(max(30.0, 150.0 * math.tan(turn / 2)), abs=1.0)
    # A huge turn radius cannot start the turn before half the leg.
    assert switch_distance(5_000.0, (1_000.0, 1_000.0)) == pytest.approx(500.0, abs=1.0)


def test_no_turn_lead_on_the_last_waypoint():
    assert switch_distance(150.0, None) == pytest.approx(30.0, abs=1.0)


# --- DO commands ---------------------------------------------------------------------------


def test_do_change_speed_sets_the_setpoint_speed():
    items = [
        wp(0, (500.0, 0.0)),
        speed(1, 22.0),
        wp(2, (1_000.0, 0.0)),
        speed(3, -2.0),  # back to cruise (-1 would be "no change", as the spec has it)
        wp(4, (1_500.0, 0.0)),
    ]
    ex = executor(items)
    reached, setpoints, _ = fly_lines(ex)
    assert reached == [0, 2, 4]  # DO items are not reported as reached
    by_target: dict[int, set[float | str]] = {0: set(), 2: set(), 4: set()}
    for sp in setpoints:
        if sp.kind == Kind.LINE:
            k = round(sp.b[0] / 500.0) * 2 - 2
            by_target[k].add("nan" if math.isnan(sp.speed) else sp.speed)
    assert by_target == {0: {"nan"}, 2: {22.0}, 4: {"nan"}}


def test_changed_speed_carries_into_a_loiter():
    items = [
        speed(0, 19.0),
        item(1, d.MAV_CMD_NAV_LOITER_UNLIM, (500.0, 0.0), z=100.0, p3=100.0),
    ]
    ex = executor(items)
    sp = ex.step((0.0, 0.0), 180.0, 0.0)
    assert sp.kind == Kind.CIRCLE and sp.speed == 19.0


def test_gimbal_video_and_yaw_items_are_passed_over_and_the_legs_flown_as_without_them():
    """A region of interest 2 km off, a gimbal's angles, a video start and a yaw: nothing on
    board acts on them, so the aircraft flies the waypoints either side as if they were not
    there, never towards the region of interest."""
    a, b = (500.0, 0.0), (500.0, 500.0)
    aims = [
        item(1, d.MAV_CMD_DO_SET_ROI_LOCATION, (2_000.0, -2_000.0), z=10.0),
        item(2, d.MAV_CMD_DO_MOUNT_CONTROL, p1=-45.0),
        item(3, d.MAV_CMD_VIDEO_START_CAPTURE),
        item(4, d.MAV_CMD_CONDITION_YAW, p1=90.0),
    ]
    with_aims = executor([wp(0, a), *aims, wp(5, b)])
    reached, setpoints, end = fly_lines(with_aims)
    plain_reached, plain_setpoints, plain_end = fly_lines(executor([wp(0, a), wp(1, b)]))
    assert reached == [0, 5] and plain_reached == [0, 1] and with_aims.finished
    assert [sp.b for sp in setpoints if sp.kind == Kind.LINE] == [
        sp.b for sp in plain_setpoints if sp.kind == Kind.LINE
    ]
    assert end == plain_end


def test_do_jump_repeats_the_loop_twice_more_then_continues():
    a, b, c = (500.0, 0.0), (500.0, 500.0), (0.0, 500.0)
    items = [wp(0, a), wp(1, b), jump(2, 0, 2), wp(3, c)]
    ex = executor(items)
    reached, _, _ = fly_lines(ex)
    assert reached == [0, 1, 0, 1, 0, 1, 3]
    assert ex.finished


def test_do_jump_forever_keeps_looping():
    items = [wp(0, (500.0, 0.0)), wp(1, (500.0, 500.0)), jump(2, 0, -1), wp(3, (0.0, 500.0))]
    ex = executor(items)
    reached: list[int] = []
    pos = (0.0, 0.0)
    for t in range(3_000):  # long enough for several laps
        sp = ex.step(pos, 180.0, float(t))
        reached += ex.drain_reached()
        pos = towards(pos, sp.b, 10.0)
    assert not ex.finished
    assert len(reached) > 10 and 3 not in reached
    assert reached == [k % 2 for k in range(len(reached))]  # 0, 1, 0, 1, ...


@pytest.mark.timeout(10)
@pytest.mark.parametrize("turn_radius", [0.0, 150.0])
def test_do_jump_loop_without_nav_items_does_not_hang(turn_radius: float):
    items = [wp(0, (500.0, 0.0)), speed(1, 20.0), jump(2, 1, -1)]
    ex = executor(items)
    first = ex.step((0.0, 0.0), 180.0, 0.0, turn_radius)
    assert first.kind == Kind.LINE
    sp = ex.step((490.0, 0.0), 180.0, 1.0, turn_radius)  # reaches the waypoint, then spins
    assert ex.drain_reached() == [0]
    assert sp.kind == Kind.CIRCLE  # it stopped in a holding circle ...
    assert sp.b == pytest.approx((500.0, 0.0), abs=0.05)  # ... where it was going
    again = ex.step((480.0, 50.0), 180.0, 2.0, turn_radius)
    assert again == sp


@pytest.mark.timeout(10)
def test_do_jumps_to_each_other_do_not_hang_at_the_start():
    ex = executor([jump(0, 1, -1), jump(1, 0, -1)], pos=(30.0, 40.0))
    sp = ex.step((30.0, 40.0), 150.0, 0.0, 150.0)
    assert sp.kind == Kind.CIRCLE and sp.b == (30.0, 40.0)
    assert ex.finished


def test_a_long_finite_jump_loop_without_nav_items_is_consistent():
    repeats = 40  # two items per lap, 80 DO items to run through in one step
    items = [wp(0, (500.0, 0.0)), speed(1, 20.0), jump(2, 1, repeats), wp(3, (500.0, 800.0))]
    ex = executor(items)
    ex.step((0.0, 0.0), 180.0, 0.0)
    sp = ex.step((490.0, 0.0), 180.0, 1.0)
    assert ex.drain_reached() == [0]
    # Either it runs the finite loop out and flies on to the next waypoint ...
    if not ex.finished:
        assert sp.kind == Kind.LINE and sp.b == pytest.approx((500.0, 800.0), abs=0.05)
        reached, setpoints, _ = fly_lines(ex, pos=(490.0, 0.0))
        assert reached == [3] and setpoints[-1].b == pytest.approx((500.0, 800.0), abs=0.05)
        return
    # ... or, having said the mission is finished, it stays finished on its hold circle.
    for t in range(2, 10):
        again = ex.step((490.0, 10.0), 180.0, float(t))
        assert ex.finished and again == sp
