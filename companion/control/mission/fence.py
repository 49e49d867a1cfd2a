"""The geofence from the fence mission type: where the aircraft may and may not fly.

Inclusion polygons and circles: the aircraft must be inside every one of them (one is
the usual case); exclusion polygons and circles: it must be outside all of them. Polygons are kept
in a north/east frame in metres around the first fence point (companion.control.mission.zones).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from companion.control.mission.items import MissionItem
from companion.control.mission.zones import CircleZone, PolygonZone, Zone
from companion.geodesy import LocalFrame
from mavlink_dialect import companion as d

POLYGONS = {
    d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION: True,
    d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_EXCLUSION: False,
}
CIRCLES = {
    d.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION: True,
    d.MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION: False,
}


@dataclass
class Fence:
    """Zones in metres north/east of the frame's origin."""

    frame: LocalFrame
    inclusions: list[Zone] = field(default_factory=list)
    exclusions: list[Zone] = field(default_factory=list)

    @classmethod
    def from_items(cls, items: list[MissionItem]) -> Fence:
        """Build from stored fence items (polygon vertices carry their count in param1)."""
        origin = (items[0].x / 1e7, items[0].y / 1e7) if items else (0.0, 0.0)
        fence = cls(LocalFrame(*origin))
        frame = fence.frame
        i = 0
        while i < len(items):
            item = items[i]
            if item.command in POLYGONS:
                count = max(3, round(item.param1))
                vertices = [frame.ne(v.x / 1e7, v.y / 1e7) for v in items[i : i + count]]
                zone: Zone = PolygonZone(_without_repeats(vertices))
                i += count
                (fence.inclusions if POLYGONS[item.command] else fence.exclusions).append(zone)
                continue
            if item.command in CIRCLES:
                centre = frame.ne(item.x / 1e7, item.y / 1e7)
                zone = CircleZone(centre, abs(item.param1))
                (fence.inclusions if CIRCLES[item.command] else fence.exclusions).append(zone)
            i += 1
        return fence

    @property
    def empty(self) -> bool:
        """No zone at all: nothing to breach."""
        return not self.inclusions and not self.exclusions

    def breach(self, lat_deg: float, lon_deg: float) -> str | None:
        """Why this position breaches the fence, or None when it is allowed."""
        if not (math.isfinite(lat_deg) and math.isfinite(lon_deg)):
            return None
        here = self.frame.ne(lat_deg, lon_deg)
        if any(not zone.covers(here) for zone in self.inclusions):
            return "outside the fence"
        if any(zone.contains(here) for zone in self.exclusions):
            return "inside an exclusion zone"
        return None

    def keeps(self, a: tuple[float, float], b: tuple[float, float], width_m: float) -> bool:
        """Whether the strip ``width_m`` either side of the straight path from ``a`` to
        ``b`` (lat, lon in degrees; the same point twice: a disc) breaches nothing: inside
        every inclusion zone, clear of every exclusion zone. A planned track is judged by
        this before it is flown (the landing pattern Land builds, landing_pattern.py)."""
        pa, pb = self.frame.ne(*a), self.frame.ne(*b)
        inside = all(zone.holds(pa, pb, width_m) for zone in self.inclusions)
        return inside and all(zone.clear_of(pa, pb, width_m) for zone in self.exclusions)


def honoured(items: list[MissionItem]) -> tuple[list[MissionItem], list[str]]:
    """The fence items without the zones that enclose nothing, and why each was left out.

    MAVSDK's geofence plug-in sends a placeholder circle of radius 0 at 0,0 beside the
    user's polygon; refusing the whole upload for it left the aircraft with no fence at
    all (issue 47.2). A circle of no radius or a polygon of fewer than three vertices is
    left out, the rest kept (renumbered) and checked as before; the texts tell the ground
    station which zone was ignored, and when no zone is left, that no fence is installed.
    """
    kept: list[MissionItem] = []
    notes: list[str] = []
    i = 0
    while i < len(items):
        item = items[i]
        zone = [item]
        if item.command in POLYGONS:
            # param1 counts the vertices; a count under 3 (0: not given) is no count at all.
            count = round(item.param1) if math.isfinite(item.param1) else 1
            zone = items[i : i + count] if count >= 3 else items[i:]
            zone = zone[: next((k for k, v in enumerate(zone) if v.command != item.command), None)]
        why = _empty(zone)
        if why is None:
            kept += zone
        else:
            # Within STATUSTEXT's 50 bytes: one message, whatever the ground station.
            notes.append(f"Fence item {item.seq} ignored: {_zone_name(item)} {why}")
        i += len(zone)
    if notes and not any(it.command in POLYGONS or it.command in CIRCLES for it in kept):
        notes.append("Fence: no zone left, no fence installed")
    return [replace(it, seq=k) for k, it in enumerate(kept)], notes


def _empty(zone: list[MissionItem]) -> str | None:
    """Why a zone encloses nothing, or None."""
    first = zone[0]
    if first.command in CIRCLES and first.param1 == 0:  # NaN is refused by the checks
        return "radius 0"
    if first.command in POLYGONS and math.isfinite(first.param1) and len(zone) < 3:
        return f"of {len(zone)} pts"
    return None


def _zone_name(item: MissionItem) -> str:
    kind = "polygon" if item.command in POLYGONS else "circle"
    inclusion = POLYGONS.get(item.command, CIRCLES.get(item.command))
    if inclusion is None:
        return "return point"
    return f"{'inclusion' if inclusion else 'exclusion'} {kind}"


def _without_repeats(vertices: list[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    """The vertices without one repeated in a row (or the first repeated at the end)."""
    kept = [v for i, v in enumerate(vertices) if i == 0 or v != vertices[i - 1]]
    while len(kept) > 1 and kept[-1] == kept[0]:
        kept.pop()
    return tuple(kept)
