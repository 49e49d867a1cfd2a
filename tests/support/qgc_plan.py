"""QGroundControl .plan files as its Plan view saves them, for tests that fly one."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any


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
