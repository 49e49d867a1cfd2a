"""QGroundControl ``.plan`` files: import to mission/fence/rally items and export back.

A plan is JSON: ``mission.items`` (SimpleItems with command, frame, params[7],
autoContinue; of the ComplexItems the fixed-wing landing pattern is expanded to the items
QGroundControl uploads for it, the others are refused by name), ``geoFence`` (polygons
and circles with inclusion flags, the breach return point) and ``rallyPoints.points``.
Exported plans hold all three as QGroundControl 4.4 writes them (it refuses a polygon
without its ``version`` and ``inclusion``, a circle without ``inclusion``), so loading an
exported plan stores the same items again; ``geoFence`` and ``rallyPoints`` are always
there, which MAVSDK's importer requires.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

from companion.control.mission.executor import RELATIVE_FRAMES
from companion.control.mission.fence import CIRCLES, POLYGONS
from companion.control.mission.items import GLOBAL_FRAMES, MissionItem, check_mission
from companion.params.atomic import atomic_write_text
from mavlink_dialect import companion as d


class PlanError(ValueError):
    """A plan the vehicle cannot take, with the reason."""


def _num(value: Any) -> float:
    return math.nan if value is None else float(value)


def _simple(raw: dict[str, Any], seq: int) -> MissionItem:
    params = [_num(p) for p in (raw.get("params") or [])] + [0.0] * 7
    lat, lon = params[4], params[5]
    return MissionItem(
        seq=seq,
        frame=int(raw.get("frame", d.MAV_FRAME_GLOBAL_RELATIVE_ALT)),
        command=int(raw["command"]),
        current=0,
        autocontinue=int(bool(raw.get("autoContinue", True))),
        param1=params[0],
        param2=params[1],
        param3=params[2],
        param4=params[3],
        x=0 if math.isnan(lat) else round(lat * 1e7),
        y=0 if math.isnan(lon) else round(lon * 1e7),
        z=0.0 if math.isnan(params[6]) else params[6],
    )


LANDING_PATTERN = "fwLandingPattern"
RALLY_FRAMES = "companionFrames"  # rally points' frames, when one is not above home


def _landing(raw: dict[str, Any]) -> list[dict[str, Any]]:
    """The items QGroundControl uploads for a fixed-wing landing pattern: DO_LAND_START,
    the camera stops asked for, the final approach (LOITER_TO_ALT leaving on the tangent
    towards the landing point, or a waypoint), NAV_LAND."""
    frame = (
        d.MAV_FRAME_GLOBAL_RELATIVE_ALT if raw.get("altitudesAreRelative", True)
        else d.MAV_FRAME_GLOBAL
    )  # fmt: skip
    approach = raw.get("landingApproachCoordinate", raw.get("loiterCoordinate"))
    if approach is None:  # else a TypeError about None would be the plan's error
        raise KeyError("landingApproachCoordinate")
    land = raw["landCoordinate"]
    out = [{"command": d.MAV_CMD_DO_LAND_START, "frame": d.MAV_FRAME_MISSION, "params": [0] * 7}]
    if raw.get("stopTakingPhotos", False):
        out.append({"command": d.MAV_CMD_IMAGE_STOP_CAPTURE, "frame": 2, "params": [0] * 7})
    if raw.get("stopTakingVideo", False):
        out.append({"command": d.MAV_CMD_VIDEO_STOP_CAPTURE, "frame": 2, "params": [0] * 7})
    if raw.get("useLoiterToAlt", True):
        radius = float(raw["loiterRadius"]) * (1.0 if raw.get("loiterClockwise", True) else -1.0)
        params = [1.0, radius, 0.0, 1.0, approach[0], approach[1], approach[2]]
        out.append({"command": d.MAV_CMD_NAV_LOITER_TO_ALT, "frame": frame, "params": params})
    else:
        params = [0.0, 0.0, 0.0, None, approach[0], approach[1], approach[2]]
        out.append({"command": d.MAV_CMD_NAV_WAYPOINT, "frame": frame, "params": params})
    params = [0.0, 0.0, 0.0, None, land[0], land[1], land[2]]
    out.append({"command": d.MAV_CMD_NAV_LAND, "frame": frame, "params": params})
    return out


def _mission_items(plan: dict[str, Any], path: Path) -> list[MissionItem]:
    items: list[MissionItem] = []
    jump_ids: dict[int, int] = {}  # QGroundControl's doJumpId → our sequence number
    for index, raw in enumerate(plan.get("mission", {}).get("items", [])):
        if raw.get("complexItemType") == LANDING_PATTERN:
            try:
                items += [_simple(r, len(items) + k) for k, r in enumerate(_landing(raw))]
            except (KeyError, TypeError, ValueError, IndexError) as exc:
                raise PlanError(f"{path}: mission item {index}: {exc}") from None
            continue
        if raw.get("type") != "SimpleItem":
            kind = raw.get("complexItemType", raw.get("type"))
            raise PlanError(f"{path}: mission item {index}: {kind} items are not supported")
        try:
            items.append(_simple(raw, len(items)))
        except (KeyError, TypeError, ValueError) as exc:
            raise PlanError(f"{path}: mission item {index}: {exc}") from None
        if "doJumpId" in raw:
            jump_ids[int(raw["doJumpId"])] = len(items) - 1
    for i, item in enumerate(items):
        if item.command == d.MAV_CMD_DO_JUMP:
            target = jump_ids.get(round(item.param1))
            if target is None:
                raise PlanError(
                    f"{path}: mission item {i}: DO_JUMP to unknown item {item.param1:g}"
                )
            items[i] = replace(item, param1=float(target))
    return items


def _fence_items(plan: dict[str, Any]) -> list[MissionItem]:
    fence = plan.get("geoFence", {})
    items: list[MissionItem] = []
    for poly in fence.get("polygons", []):
        points = poly.get("polygon", [])
        inclusion = poly.get("inclusion", True)
        cmd = (
            d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION
            if inclusion
            else d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_EXCLUSION
        )
        for lat, lon in points:
            items.append(_fence_item(len(items), cmd, len(points), lat, lon, 1))
    for circle in fence.get("circles", []):
        cmd = (
            d.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION
            if circle.get("inclusion", True)
            else d.MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION
        )
        lat, lon = circle["circle"]["center"]
        items.append(_fence_item(len(items), cmd, circle["circle"]["radius"], lat, lon, 1))
    if "breachReturn" in fence:  # [lat, lon, alt]: uploaded by QGroundControl after the zones
        lat, lon, alt = fence["breachReturn"]
        point = _fence_item(len(items), d.MAV_CMD_NAV_FENCE_RETURN_POINT, 0.0, lat, lon, 1)
        items.append(replace(point, frame=d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, z=float(alt)))
    return items


def _fence_item(seq: int, cmd: int, p1: float, lat: float, lon: float, mtype: int) -> MissionItem:
    return MissionItem(
        seq,
        d.MAV_FRAME_GLOBAL_INT,
        cmd,
        0,
        1,
        float(p1),
        0.0,
        0.0,
        0.0,
        round(lat * 1e7),
        round(lon * 1e7),
        0.0,
        mtype,
    )


def load_plan(path: str | Path) -> dict[int, list[MissionItem]]:
    """The items of each mission type (0 mission, 1 fence, 2 rally) in a .plan file."""
    path = Path(path)
    try:
        plan = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise PlanError(f"{path}: not a readable plan: {exc}") from None
    if plan.get("fileType") != "Plan":
        raise PlanError(f"{path}: fileType is not 'Plan'")
    points = plan.get("rallyPoints", {})
    frames = points.get(RALLY_FRAMES, []) if isinstance(points, dict) else None
    if not isinstance(frames, list) or not all(
        isinstance(f, int) and f in GLOBAL_FRAMES for f in frames
    ):
        raise PlanError(f"{path}: rallyPoints: {RALLY_FRAMES} must list global frames")
    rally = [
        MissionItem(
            i,
            frames[i] if i < len(frames) else d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
            d.MAV_CMD_NAV_RALLY_POINT,
            0,
            1,
            0.0,
            0.0,
            0.0,
            0.0,
            round(p[0] * 1e7),
            round(p[1] * 1e7),
            float(p[2]),
            2,
        )
        for i, p in enumerate(points.get("points", []))
    ]
    try:
        fence = _fence_items(plan)
    except (KeyError, TypeError, ValueError) as exc:
        raise PlanError(f"{path}: geoFence: {exc!r}") from None
    mission = _mission_items(plan, path)
    return {0: mission, 1: fence, 2: rally}


def plan_json(items: dict[int, list[MissionItem]]) -> dict[str, Any]:
    """A QGroundControl plan holding these items: mission, geofence and rally points."""
    mission = [
        {
            "type": "SimpleItem",
            "command": it.command,
            "frame": it.frame,
            "autoContinue": bool(it.autocontinue),
            "doJumpId": it.seq + 1,
            "params": _export_params(it),
        }
        for it in items.get(0, [])
    ]
    first = items.get(0, [None])[0] if items.get(0) else None
    home = [first.x / 1e7, first.y / 1e7, 0.0] if first else [0.0, 0.0, 0.0]
    rally_items = items.get(2, [])
    points = [[it.x / 1e7, it.y / 1e7, it.z] for it in rally_items]
    rally: dict[str, Any] = {"version": 2, "points": points}
    if any(it.frame not in RELATIVE_FRAMES for it in rally_items):
        # A .plan's rally altitudes are above home: a point stored above sea level keeps
        # its frame in a key of ours, which QGroundControl passes over.
        rally[RALLY_FRAMES] = [it.frame for it in rally_items]
    return {
        "fileType": "Plan",
        "version": 1,
        "groundStation": "companion",
        "mission": {
            "version": 2,
            "firmwareType": 0,
            "vehicleType": 1,
            "cruiseSpeed": 22,
            "hoverSpeed": 5,
            "plannedHomePosition": home,
            "items": mission,
        },
        "geoFence": _fence_json(items.get(1, [])),
        "rallyPoints": rally,
    }


def _export_params(it: MissionItem) -> list[float | None]:
    p1 = it.param1 + 1 if it.command == d.MAV_CMD_DO_JUMP else it.param1  # back to doJumpId
    values = [p1, it.param2, it.param3, it.param4, it.x / 1e7, it.y / 1e7, it.z]
    return [None if isinstance(v, float) and math.isnan(v) else v for v in values]


def _fence_json(items: list[MissionItem]) -> dict[str, Any]:
    """``geoFence`` as QGroundControl 4.4 writes it; polygon vertices are grouped as the
    vehicle's fence reads them (companion.control.mission.fence: the count in param1)."""
    polygons: list[dict[str, Any]] = []
    circles: list[dict[str, Any]] = []
    fence: dict[str, Any] = {"version": 2, "polygons": polygons, "circles": circles}
    i = 0
    while i < len(items):
        item = items[i]
        if item.command in POLYGONS:
            vertices = items[i : i + max(3, round(item.param1))]
            points = [[v.x / 1e7, v.y / 1e7] for v in vertices]
            polygons.append({"inclusion": POLYGONS[item.command], "version": 1, "polygon": points})
            i += len(vertices)
            continue
        if item.command in CIRCLES:
            circle = {"center": [item.x / 1e7, item.y / 1e7], "radius": item.param1}
            circles.append({"inclusion": CIRCLES[item.command], "version": 1, "circle": circle})
        elif item.command == d.MAV_CMD_NAV_FENCE_RETURN_POINT:
            fence["breachReturn"] = [item.x / 1e7, item.y / 1e7, item.z]
        i += 1
    return fence


def plan_counts(plan: dict[str, Any]) -> dict[int, int]:
    """How many items of each mission type a plan written by ``plan_json`` holds."""
    fence = plan["geoFence"]
    vertices = sum(len(p["polygon"]) for p in fence["polygons"])
    fenced = vertices + len(fence["circles"]) + ("breachReturn" in fence)
    return {0: len(plan["mission"]["items"]), 1: fenced, 2: len(plan["rallyPoints"]["points"])}


def save_plan(path: str | Path, items: dict[int, list[MissionItem]]) -> dict[int, int]:
    """Write a .plan file with the mission, geofence and rally points; the count of each
    written (by mission type)."""
    plan = plan_json(items)
    atomic_write_text(Path(path), json.dumps(plan, indent=2), shared=True)
    return plan_counts(plan)


def checked_plan(path: str | Path) -> dict[int, list[MissionItem]]:
    """``load_plan``, then every list checked as an upload would be; PlanError on refusal."""
    lists = load_plan(path)
    for mission_type, items in lists.items():
        result = check_mission(items)
        if result != d.MAV_MISSION_ACCEPTED:
            name = d.enums["MAV_MISSION_RESULT"][result].name
            raise PlanError(f"{path}: mission type {mission_type} refused: {name}")
    return lists
