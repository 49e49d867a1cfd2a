"""QGroundControl .plan files as its Plan view saves them, for tests that fly one."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from companion.geodesy import LocalFrame
from mavlink_dialect import companion as d

# The runway's home, and a plan's points from it (north, east m): a take-off east, A 3 km
# east, B 1.5 km north of A.
HOME = LocalFrame(-37.9105, 145.1340)
TAKEOFF, A, B = (0.0, 600.0), (0.0, 3000.0), (1500.0, 3000.0)


def simple_item(command: int, frame: int, params: list[Any], seq: int) -> dict[str, Any]:
    """A SimpleItem (``doJumpId`` ``seq``, from 1); params as QGroundControl writes them
    (None where it leaves a value out)."""
    return {"type": "SimpleItem", "autoContinue": True, "command": command,
            "doJumpId": seq, "frame": frame, "params": params}  # fmt: skip


def write_plan(path: Path, items: list[dict[str, Any]], home: tuple[float, float, float]) -> Path:
    """A plan of ``items`` with no fence and no rally points, planned from ``home``
    (latitude, longitude, altitude above sea level), written to ``path``."""
    mission = {"version": 2, "firmwareType": 12, "vehicleType": 1, "cruiseSpeed": 15,
               "hoverSpeed": 5, "plannedHomePosition": list(home), "items": items}  # fmt: skip
    plan = {"fileType": "Plan", "version": 1, "groundStation": "QGroundControl",
            "mission": mission, "geoFence": {"version": 2, "polygons": [], "circles": []},
            "rallyPoints": {"version": 2, "points": []}}  # fmt: skip
    path.write_text(json.dumps(plan))
    return path


def item_at_a_plan(path: Path, command: int, params: list[Any]) -> Path:
    """Take-off, waypoint A at 100 m, the item (frame MISSION, as QGroundControl 4.4.5
    saves a DO item), waypoint B: the item acts over A, kilometres after the runway."""

    def at(ne: tuple[float, float], alt: float) -> list[Any]:
        return [*HOME.latlon(*ne), alt]

    items = [
        simple_item(d.MAV_CMD_NAV_TAKEOFF, 3, [15, 0, 0, None, *at(TAKEOFF, 60.0)], 1),
        simple_item(d.MAV_CMD_NAV_WAYPOINT, 3, [0, 0, 0, None, *at(A, 100.0)], 2),
        simple_item(command, 2, params, 3),
        simple_item(d.MAV_CMD_NAV_WAYPOINT, 3, [0, 0, 0, None, *at(B, 100.0)], 4),
    ]
    return write_plan(path, items, (HOME.lat0, HOME.lon0, 126))
