"""The geofence's zones as plane figures in metres north/east: polygons and circles.

Written here rather than taken from shapely: a fence asks only whether a point is inside a
simple polygon or a circle, and whether a polygon is simple, while shapely (GEOS) costs each
vehicle ~9 MB of memory. A circle is now exact, where shapely's was a 128-sided polygon.
tests/unit/control/mission/test_zones.py holds these answers to shapely's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

Point = tuple[float, float]  # north, east, m


def _cross(o: Point, a: Point, b: Point) -> float:
    """Twice the signed area of triangle o-a-b (> 0: b lies left of o->a)."""
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _on_segment(p: Point, a: Point, b: Point) -> bool:
    """Whether p lies on the closed segment a-b."""
    if _cross(a, b, p) != 0.0:
        return False
    return min(a[0], b[0]) <= p[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= p[1] <= max(a[1], b[1])


def _segments_meet(a: Point, b: Point, c: Point, d: Point) -> bool:
    """Whether the closed segments a-b and c-d share a point."""
    d1, d2 = _cross(c, d, a), _cross(c, d, b)
    d3, d4 = _cross(a, b, c), _cross(a, b, d)
    if ((d1 > 0) != (d2 > 0)) and ((d3 > 0) != (d4 > 0)) and 0.0 not in (d1, d2, d3, d4):
        return True
    return (
        _on_segment(a, c, d) or _on_segment(b, c, d) or _on_segment(c, a, b) or _on_segment(d, a, b)
    )


def point_to_segment(p: Point, a: Point, b: Point) -> float:
    """The distance from p to the closed segment a-b (m, in a local frame)."""
    dn, de = b[0] - a[0], b[1] - a[1]
    length2 = dn * dn + de * de
    k = 0.0 if length2 == 0.0 else ((p[0] - a[0]) * dn + (p[1] - a[1]) * de) / length2
    k = max(0.0, min(1.0, k))
    return math.hypot(p[0] - a[0] - k * dn, p[1] - a[1] - k * de)


def _segment_gap(a: Point, b: Point, c: Point, d: Point) -> float:
    """The least distance between the closed segments a-b and c-d (0 where they meet)."""
    if _segments_meet(a, b, c, d):
        return 0.0
    return min(
        point_to_segment(a, c, d),
        point_to_segment(b, c, d),
        point_to_segment(c, a, b),
        point_to_segment(d, a, b),
    )


@dataclass(frozen=True)
class PolygonZone:
    """A polygon given by its vertices in order (not repeated at the end)."""

    vertices: tuple[Point, ...]

    @cached_property
    def edges(self) -> list[tuple[Point, Point]]:
        """Each vertex to the next, the last to the first (made once: the commander asks
        whether it is inside ten times a second)."""
        v = self.vertices
        return [(v[i], v[(i + 1) % len(v)]) for i in range(len(v))]

    @property
    def area(self) -> float:
        """Area in m² (shoelace), whichever way the vertices turn."""
        return abs(sum(_cross((0.0, 0.0), a, b) for a, b in self.edges)) / 2

    @property
    def is_valid(self) -> bool:
        """A simple polygon: three or more finite vertices, no edge touching another
        except its two neighbours at their shared vertices, and an area."""
        v = self.vertices
        if len(v) < 3 or not all(math.isfinite(c) for p in v for c in p):
            return False
        edges = self.edges
        n = len(edges)
        for i in range(n):
            a, b = edges[i]
            if a == b:
                return False
            for j in range(i + 1, n):
                c, d = edges[j]
                if j == i + 1 or (i == 0 and j == n - 1):  # neighbours: share one vertex
                    shared, far = (b, d) if j == i + 1 else (a, c)
                    other = a if j == i + 1 else b
                    if _on_segment(far, *edges[i]) or _on_segment(other, shared, far):
                        return False  # folding back along the neighbour
                elif _segments_meet(a, b, c, d):
                    return False
        return self.area > 0

    def _on_boundary(self, p: Point) -> bool:
        return any(_on_segment(p, a, b) for a, b in self.edges)

    def _inside(self, p: Point) -> bool:
        """Crossing-number test: a ray from p towards +east crosses the boundary oddly."""
        inside = False
        for a, b in self.edges:
            if (a[0] > p[0]) != (b[0] > p[0]):
                east = a[1] + (p[0] - a[0]) * (b[1] - a[1]) / (b[0] - a[0])
                if p[1] < east:
                    inside = not inside
        return inside

    def covers(self, p: Point) -> bool:
        """Inside or on the boundary."""
        return self._on_boundary(p) or self._inside(p)

    def contains(self, p: Point) -> bool:
        """Strictly inside."""
        return not self._on_boundary(p) and self._inside(p)

    def _clear_of_boundary(self, a: Point, b: Point, width: float) -> bool:
        """The segment a-b nowhere on the boundary nor nearer it than ``width``."""
        gap = min(_segment_gap(a, b, c, d) for c, d in self.edges)
        return gap > 0.0 and gap >= width

    def holds(self, a: Point, b: Point, width: float) -> bool:
        """Whether every point within ``width`` of the segment a-b is inside: both ends
        inside and the segment nowhere on the boundary nor nearer it than ``width``."""
        return self.covers(a) and self.covers(b) and self._clear_of_boundary(a, b, width)

    def clear_of(self, a: Point, b: Point, width: float) -> bool:
        """Whether no point within ``width`` of the segment a-b is inside (an end outside
        and the boundary never that near: neither crosses nor encloses the other)."""
        return not self.covers(a) and self._clear_of_boundary(a, b, width)


@dataclass(frozen=True)
class CircleZone:
    """A circle about a centre."""

    centre: Point
    radius_m: float

    @property
    def area(self) -> float:
        return math.pi * self.radius_m**2

    @property
    def is_valid(self) -> bool:
        """A finite centre and a finite radius above zero."""
        finite = math.isfinite(self.radius_m) and all(math.isfinite(c) for c in self.centre)
        return finite and self.radius_m > 0

    def _distance(self, p: Point) -> float:
        return math.hypot(p[0] - self.centre[0], p[1] - self.centre[1])

    def covers(self, p: Point) -> bool:
        return self._distance(p) <= self.radius_m

    def contains(self, p: Point) -> bool:
        return self._distance(p) < self.radius_m

    def holds(self, a: Point, b: Point, width: float) -> bool:
        """Whether every point within ``width`` of the segment a-b is inside (a circle
        is convex: both ends far enough inside is enough)."""
        return max(self._distance(a), self._distance(b)) + width <= self.radius_m

    def clear_of(self, a: Point, b: Point, width: float) -> bool:
        """Whether no point within ``width`` of the segment a-b is inside."""
        return point_to_segment(self.centre, a, b) >= self.radius_m + width


Zone = PolygonZone | CircleZone
