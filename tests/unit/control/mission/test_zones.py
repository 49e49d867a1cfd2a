"""The fence's own plane geometry answers as shapely (GEOS) does, circles exactly."""

from __future__ import annotations

import math

from hypothesis import assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import Point as ShapelyPoint
from shapely.geometry import Polygon as ShapelyPolygon

from companion.control.mission.zones import CircleZone, PolygonZone

coordinate = st.integers(-50, 50).map(float)  # a grid: boundaries are hit exactly, often
point = st.tuples(coordinate, coordinate)
polygon = st.lists(point, min_size=3, max_size=8, unique=True).map(tuple)


@settings(max_examples=600, deadline=None)
@given(polygon)
def test_validity_and_area_are_shapelys(vertices):
    zone, reference = PolygonZone(vertices), ShapelyPolygon(vertices)
    assert zone.is_valid == reference.is_valid
    if reference.is_valid:
        assert math.isclose(zone.area, reference.area, abs_tol=1e-9)


@settings(max_examples=600, deadline=None)
@given(polygon, st.lists(point, min_size=1, max_size=20))
def test_containment_is_shapelys_on_and_off_the_boundary(vertices, points):
    reference = ShapelyPolygon(vertices)
    assume(reference.is_valid)
    zone = PolygonZone(vertices)
    for p in [*points, *vertices]:
        here = ShapelyPoint(p)
        assert zone.covers(p) == reference.covers(here), p
        assert zone.contains(p) == reference.contains(here), p


def test_a_square_fence_has_its_edges_and_corners_inside_but_not_strictly():
    square = PolygonZone(((0.0, 0.0), (0.0, 100.0), (100.0, 100.0), (100.0, 0.0)))
    assert square.is_valid and square.area == 10_000
    for edge_point in ((0.0, 0.0), (50.0, 100.0), (100.0, 37.5)):
        assert square.covers(edge_point) and not square.contains(edge_point)
    assert square.contains((50.0, 50.0))
    assert not square.covers((100.001, 50.0))


def test_a_bow_tie_or_a_spike_is_not_a_fence():
    assert not PolygonZone(((0.0, 0.0), (10.0, 10.0), (10.0, 0.0), (0.0, 10.0))).is_valid
    assert not PolygonZone(((0.0, 0.0), (10.0, 0.0), (5.0, 0.0))).is_valid  # no area
    spike = ((0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (10.0, 20.0), (10.0, 5.0), (0.0, 10.0))
    assert not PolygonZone(spike).is_valid
    assert not PolygonZone(((0.0, 0.0), (math.nan, 1.0), (1.0, 0.0))).is_valid


def test_a_circle_is_exact_where_a_polygon_of_it_was_not():
    circle = CircleZone((0.0, 0.0), 100.0)
    between_chord_and_arc = (0.0, 99.99)  # a 128-gon's edge there lies 99.97-100 m out
    assert circle.covers(between_chord_and_arc) and circle.contains(between_chord_and_arc)
    assert circle.covers((100.0, 0.0)) and not circle.contains((100.0, 0.0))
    assert not circle.covers((70.8, 70.8))
    assert not CircleZone((0.0, 0.0), math.inf).is_valid
    assert not CircleZone((0.0, 0.0), 0.0).is_valid  # no area: encloses nothing
    assert not CircleZone((0.0, 0.0), -5.0).is_valid


# An L: the square 0..100 x 0..100 without its north-east quarter.
ELL = PolygonZone(
    ((0.0, 0.0), (100.0, 0.0), (100.0, 50.0), (50.0, 50.0), (50.0, 100.0), (0.0, 100.0))
)


def test_a_path_is_held_only_when_it_and_its_width_stay_inside():
    assert ELL.holds((10.0, 10.0), (90.0, 10.0), 5.0)
    assert not ELL.holds((10.0, 10.0), (90.0, 10.0), 15.0)  # the width reaches the edge
    # Both ends inside the L, the path across its missing corner: not held.
    assert ELL.covers((90.0, 40.0)) and ELL.covers((40.0, 90.0))
    assert not ELL.holds((90.0, 40.0), (40.0, 90.0), 0.0)
    assert ELL.holds((25.0, 25.0), (25.0, 25.0), 20.0)  # a disc
    assert not ELL.holds((25.0, 25.0), (25.0, 25.0), 30.0)


def test_a_path_is_clear_of_a_zone_only_when_no_part_of_its_width_is_in_it():
    assert ELL.clear_of((75.0, 75.0), (75.0, 75.0), 20.0)  # in the missing corner
    assert not ELL.clear_of((75.0, 75.0), (75.0, 75.0), 30.0)
    assert not ELL.clear_of((-10.0, -10.0), (110.0, 110.0), 0.0)  # across it
    assert not ELL.clear_of((50.0, -500.0), (50.0, -500.0), 1000.0)  # a disc round it all
    circle = CircleZone((0.0, 0.0), 100.0)
    assert circle.holds((0.0, -50.0), (0.0, 50.0), 50.0)
    assert not circle.holds((0.0, -50.0), (0.0, 50.0), 51.0)
    assert circle.clear_of((150.0, -500.0), (150.0, 500.0), 50.0)  # passing beside it
    assert not circle.clear_of((150.0, -500.0), (150.0, 500.0), 51.0)
