"""When a landing's final is begun from a circle instead of a loop corner
(companion/control/mission/approach.py): the geometry alone, in metres north/east."""

from __future__ import annotations

from companion.control.mission.approach import turns_back_onto

RADIUS = 115.0  # the J3Cub's turn at its cruise bank
START, LAND = (0.0, -700.0), (0.0, 0.0)  # a 700 m final eastwards: six turn radii


def test_a_long_final_reached_back_along_its_own_line_is_begun_from_a_circle():
    """A go-around climbs out past the runway, then comes back to the final's first
    waypoint: a 180° loop there left a Cub 150 m beside the final in a crosswind, and it
    touched down 19 m aside."""
    assert turns_back_onto((0.0, 400.0), START, LAND, RADIUS)  # from past the runway
    assert turns_back_onto((60.0, 400.0), START, LAND, RADIUS)  # a little beside it


def test_a_long_final_reached_from_well_beside_it_keeps_its_loop_corner():
    # A downwind leg three radii out: the loop ends lined up with most of the final left.
    assert not turns_back_onto((350.0, 400.0), START, LAND, RADIUS)
    # Turning back 140° only, from beside the line.
    assert not turns_back_onto((300.0, -350.0), START, LAND, RADIUS)
    # No landing after the waypoint: nothing to line up with.
    assert not turns_back_onto((0.0, 400.0), START, None, RADIUS)


def test_a_short_final_turned_back_onto_is_begun_from_a_circle_from_anywhere():
    short = (0.0, -400.0)  # 3.5 radii
    assert turns_back_onto((350.0, 400.0), short, LAND, RADIUS)
    assert not turns_back_onto((-500.0, -400.0), short, LAND, RADIUS)  # a 90° base turn
