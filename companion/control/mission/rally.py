"""Rally points: where Return flies instead of home, chosen as ArduPlane and PX4 choose.

Return goes to the nearest rally point, or home when home is nearer (``RALLY_INCL_HOME``
1, the default of both) or when every rally point is farther than ``RALLY_LIMIT_KM`` from
the aircraft (points left over from another field). A rally point the geofence forbids
(outside an inclusion zone, inside an exclusion zone) is never chosen: the aircraft would
breach the fence there, and the breach would send it back again. The aircraft circles the
point at the point's altitude (above home unless it was uploaded in an absolute frame),
never under the floor no command may go below.

Pure: the stored rally items, the fence and positions in; the choice out.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from companion.control.mission.fence import Fence
from companion.control.mission.items import MissionItem
from companion.geodesy import LocalFrame
from companion.params import ParamDecl
from mavlink_dialect import companion as d

LIMIT_PARAM, HOME_PARAM = "RALLY_LIMIT_KM", "RALLY_INCL_HOME"
RALLY_PARAMS = (
    ParamDecl(LIMIT_PARAM, 5.0, 0.0, 1000.0, "km",
              "Return ignores a rally point farther than this from the aircraft and flies "
              "home instead (0: no limit)"),
    ParamDecl.switch(HOME_PARAM, 1.0,
                     "Return flies home when home is nearer than the nearest rally point "
                     "(0: to the nearest rally point, however near home is)"),
)  # fmt: skip
ABSOLUTE_FRAMES = frozenset({d.MAV_FRAME_GLOBAL, d.MAV_FRAME_GLOBAL_INT})


@dataclass(frozen=True)
class RallyPoint:
    """One stored rally point; ``number`` counts from 1, as ground stations list them."""

    number: int
    lat_deg: float
    lon_deg: float
    alt_m: float
    above_home: bool  # the altitude is above home, not above sea level


@dataclass(frozen=True)
class RallyPoints:
    """The rally points Return may fly to, and the numbers of those the fence forbids."""

    points: tuple[RallyPoint, ...] = ()
    forbidden: tuple[int, ...] = ()

    @classmethod
    def from_items(cls, items: list[MissionItem], fence: Fence) -> RallyPoints:
        """From the stored rally items, judged against the stored fence."""
        usable, forbidden = [], []
        for n, item in enumerate(items, start=1):
            lat, lon = item.x / 1e7, item.y / 1e7
            point = RallyPoint(n, lat, lon, item.z, item.frame not in ABSOLUTE_FRAMES)
            if fence.breach(lat, lon) is None:
                usable.append(point)
            else:
                forbidden.append(n)
        return cls(tuple(usable), tuple(forbidden))


@dataclass(frozen=True)
class ReturnChoice:
    """Where Return flies: a rally point (lat, lon, altitude above sea level), or home
    (None); and what the operator is told about it."""

    point: tuple[float, float, float] | None
    text: str


def choose_return(
    rally: RallyPoints,
    here: tuple[float, float],
    home: tuple[float, float, float],
    floor_alt: float,
    params: Mapping[str, float],
) -> ReturnChoice:
    """The rally point (or home) Return flies to from ``here`` (lat, lon); ``home`` is
    (lat, lon, altitude above sea level), ``floor_alt`` the least altitude it may fly at."""
    if not rally.points:
        return ReturnChoice(None, _forbidden_text(rally))
    frame = LocalFrame(*here)

    def distance(lat: float, lon: float) -> float:
        return math.hypot(*frame.ne(lat, lon))

    nearest = min(rally.points, key=lambda p: distance(p.lat_deg, p.lon_deg))
    far = distance(nearest.lat_deg, nearest.lon_deg)
    limit_m = params[LIMIT_PARAM] * 1000.0
    if limit_m > 0 and far > limit_m:
        why = f"rally point {nearest.number} is {far / 1000:.1f} km away, over {LIMIT_PARAM}"
        return ReturnChoice(None, f"Return: home, {why}")
    if params[HOME_PARAM] >= 0.5 and distance(home[0], home[1]) <= far:
        return ReturnChoice(None, "Return: home, nearer than any rally point")
    alt = nearest.alt_m + (home[2] if nearest.above_home else 0.0)
    raised = alt < floor_alt
    text = f"Return: to rally point {nearest.number}, {far:.0f} m away"
    if raised:
        text += f", at {floor_alt - home[2]:.0f} m above home (its own altitude is too low)"
    return ReturnChoice((nearest.lat_deg, nearest.lon_deg, max(alt, floor_alt)), text)


def _forbidden_text(rally: RallyPoints) -> str:
    if not rally.forbidden:
        return ""  # no rally point stored: home, as always, and nothing to say
    numbers = ", ".join(str(n) for n in rally.forbidden)
    points = "rally point" if len(rally.forbidden) == 1 else "rally points"
    return f"Return: home, {points} {numbers} outside the fence"
