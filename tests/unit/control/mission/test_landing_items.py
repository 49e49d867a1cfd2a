"""Landing items: what QGroundControl's landing pattern uploads is taken and flown.

The pattern (QGC's FixedWingLandingComplexItem) uploads DO_LAND_START, the camera stops
asked for, the final approach (LOITER_TO_ALT with heading required and a tangent exit, or
a waypoint) and NAV_LAND; a .plan file holding the pattern is expanded to the same items.
"""

from __future__ import annotations

import json
import math

import pytest

from companion.control.mission.executor import Kind
from companion.control.mission.items import check_mission
from companion.control.mission.plan import PlanError, checked_plan
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import (
    HOME,
    HOME_ALT,
    dist,
    executor,
    item,
    on_circle,
)

LAND = (0.0, 300.0)
CENTRE, RADIUS = (-250.0, -500.0), 250.0  # clockwise: leaves heading east for LAND


def _pattern(loiter: bool = True, photos: bool = True) -> dict:
    def ll(ne, z):  # type: ignore[no-untyped-def]
        return [*HOME.latlon(*ne), z]

    return {
        "type": "ComplexItem", "complexItemType": "fwLandingPattern", "version": 2,
        "altitudesAreRelative": True, "landCoordinate": ll(LAND, 0),
        "landingApproachCoordinate": ll(CENTRE, 50), "loiterClockwise": True,
        "loiterRadius": RADIUS, "stopTakingPhotos": photos, "stopTakingVideo": photos,
        "useLoiterToAlt": loiter, "valueSetIsDistance": True,
    }  # fmt: skip


def _plan(tmp_path, pattern: dict):  # type: ignore[no-untyped-def]
    takeoff = {"type": "SimpleItem", "command": 22, "frame": 3, "autoContinue": True,
               "params": [15, 0, 0, None, *HOME.latlon(0.0, 600.0), 100]}  # fmt: skip
    plan = {"fileType": "Plan", "mission": {"items": [takeoff, pattern]}}
    path = tmp_path / "land.plan"
    path.write_text(json.dumps(plan))
    return checked_plan(path)[0]


def test_a_landing_pattern_becomes_the_items_qgroundcontrol_uploads(tmp_path):
    items = _plan(tmp_path, _pattern())
    commands = [it.command for it in items]
    assert commands == [
        d.MAV_CMD_NAV_TAKEOFF,
        d.MAV_CMD_DO_LAND_START,
        d.MAV_CMD_IMAGE_STOP_CAPTURE,
        d.MAV_CMD_VIDEO_STOP_CAPTURE,
        d.MAV_CMD_NAV_LOITER_TO_ALT,
        d.MAV_CMD_NAV_LAND,
    ]
    loiter, land = items[4], items[5]
    assert (loiter.param1, loiter.param2, loiter.param4, loiter.z) == (1.0, RADIUS, 1.0, 50.0)
    assert land.z == 0.0 and land.frame == loiter.frame == d.MAV_FRAME_GLOBAL_RELATIVE_ALT
    assert HOME.ne(land.x / 1e7, land.y / 1e7) == pytest.approx(LAND, abs=0.05)
    assert check_mission(items) == d.MAV_MISSION_ACCEPTED


def test_a_pattern_without_loiter_ends_with_a_waypoint_then_the_landing(tmp_path):
    items = _plan(tmp_path, _pattern(loiter=False, photos=False))
    assert [it.command for it in items[1:]] == [
        d.MAV_CMD_DO_LAND_START, d.MAV_CMD_NAV_WAYPOINT, d.MAV_CMD_NAV_LAND,
    ]  # fmt: skip
    assert math.isnan(items[2].param4)


def test_a_pattern_without_an_approach_is_refused_naming_what_is_missing(tmp_path):
    pattern = _pattern()
    del pattern["landingApproachCoordinate"]
    with pytest.raises(PlanError, match="mission item 1: 'landingApproachCoordinate'"):
        _plan(tmp_path, pattern)


def test_a_landing_without_a_place_to_land_is_refused():
    here = item(0, d.MAV_CMD_NAV_LAND, None)  # lat = lon = 0: no runway to line up on
    assert check_mission([here]) == d.MAV_MISSION_INVALID_PARAM5_X


def test_loiter_to_alt_circles_down_then_leaves_on_the_tangent_to_the_runway():
    items = [
        item(0, d.MAV_CMD_DO_LAND_START),
        item(1, d.MAV_CMD_NAV_LOITER_TO_ALT, CENTRE, z=50.0, p1=1.0, p2=RADIUS),
        item(2, d.MAV_CMD_NAV_LAND, LAND, z=0.0),
    ]
    items[1] = items[1].__class__(**{**items[1].as_dict(), "param4": 1.0})
    ex = executor(items, pos=(-250.0, -900.0), alt=HOME_ALT + 100.0)
    sp = ex.step((-250.0, -900.0), HOME_ALT + 100.0, 0.0)
    assert sp.kind == Kind.CIRCLE and sp.b == pytest.approx(CENTRE, abs=0.05)
    # Round the circle clockwise, too high: it keeps circling.
    for deg in range(0, 720, 10):
        sp = ex.step(on_circle(CENTRE, RADIUS, deg), HOME_ALT + 100.0, 0.0)
        assert sp.kind == Kind.CIRCLE
    # At the height, it leaves where the circle's course points along the runway (east):
    # the circle's northern point, and the approach runs from there through LAND.
    left_at = None
    for deg in range(0, 360, 5):
        sp = ex.step(on_circle(CENTRE, RADIUS, deg), HOME_ALT + 50.0, 0.0)
        if sp.kind == Kind.LAND:
            left_at = deg
            break
    assert left_at is not None and left_at % 360 <= 30
    assert sp.b == pytest.approx(LAND, abs=0.05) and sp.alt_msl == pytest.approx(HOME_ALT)
    assert sp.a == pytest.approx((0.0, -500.0), abs=0.5)  # the planned tangent point
    assert sp.from_alt == pytest.approx(HOME_ALT + 50.0)
    assert dist(sp.a, sp.b) == pytest.approx(800.0, abs=0.5)


def test_a_circle_wider_than_planned_is_moved_to_leave_onto_the_runway_line():
    """A 100 m landing circle for an aircraft that turns no tighter than 250 m: the circle
    flown keeps the planned exit point (the circle's northern point, course east) and the
    centre moves south, so the aircraft comes off it on the runway line, not 150 m beside."""
    items = [
        item(0, d.MAV_CMD_DO_LAND_START),
        item(1, d.MAV_CMD_NAV_LOITER_TO_ALT, (-100.0, -500.0), z=50.0, p1=1.0, p2=100.0),
        item(2, d.MAV_CMD_NAV_LAND, LAND, z=0.0),
    ]
    ex = executor(items, pos=(-100.0, -900.0), alt=HOME_ALT + 50.0)
    sp = ex.step((-100.0, -900.0), HOME_ALT + 50.0, 0.0, turn_radius=250.0)
    assert sp.kind == Kind.CIRCLE and sp.radius == pytest.approx(250.0)
    assert sp.b == pytest.approx((-250.0, -500.0), abs=0.05)
    assert ex.leads_to_landing()
    left_at = next(
        deg
        for deg in range(0, 720, 5)
        if ex.step(on_circle(sp.b, 250.0, deg), HOME_ALT + 50.0, 0.0, 250.0).kind == Kind.LAND
    )
    assert on_circle(sp.b, 250.0, left_at)[0] == pytest.approx(0.0, abs=2.0)  # on the line
    assert not ex.leads_to_landing()  # on the final itself: the landing flies it


def test_only_the_item_the_final_starts_from_leads_to_the_landing():
    items = [
        item(0, d.MAV_CMD_NAV_WAYPOINT, (0.0, -2000.0), z=100.0),
        item(1, d.MAV_CMD_NAV_WAYPOINT, (0.0, -800.0), z=50.0),
        item(2, d.MAV_CMD_DO_CHANGE_SPEED, p2=20.0),
        item(3, d.MAV_CMD_NAV_LAND, LAND, z=0.0),
    ]
    ex = executor(items, pos=(0.0, -2500.0), alt=HOME_ALT + 100.0)
    ex.step((0.0, -2500.0), HOME_ALT + 100.0, 0.0)
    assert ex.current == 0 and not ex.leads_to_landing()
    ex.step((0.0, -2000.0), HOME_ALT + 100.0, 0.0)
    assert ex.current == 1 and ex.leads_to_landing()


def test_a_landing_circle_descends_below_its_height_for_a_final_no_steeper_than_allowed():
    """A 50 m circle 800 m from the point is a 3.6° final; with the steepest final at 2°
    the circle goes down to 800 m · tan 2° = 27.9 m, and the landing's path starts there."""
    items = [
        item(0, d.MAV_CMD_NAV_LOITER_TO_ALT, CENTRE, z=50.0, p1=1.0, p2=RADIUS),
        item(1, d.MAV_CMD_NAV_LAND, LAND, z=0.0),
    ]
    ex = executor(items, pos=(-250.0, -900.0), alt=HOME_ALT + 50.0)
    ex.config.final_slope_max = math.radians(2.0)
    low = HOME_ALT + 800.0 * math.tan(math.radians(2.0))
    sp = ex.step((-250.0, -900.0), HOME_ALT + 50.0, 0.0)
    assert sp.kind == Kind.CIRCLE and sp.alt_msl == pytest.approx(low, abs=0.1)
    for deg in range(0, 720, 5):
        sp = ex.step(on_circle(CENTRE, RADIUS, deg), low, 0.0)
        if sp.kind == Kind.LAND:
            break
    assert sp.kind == Kind.LAND and sp.from_alt == pytest.approx(low, abs=0.1)


def test_a_landing_circle_descends_for_a_glide_no_steeper_than_allowed_down_to_the_flare():
    """The glide path ends where the flare begins, before the point: the C172's flare from
    a 5° glide begins about 110 m out at 5 m, so a 227 m final from the 20 m that 5° to the
    point allows was glided at 8°; it dived at its least pitch to 34 m/s and floated 42 m
    long. The circle now goes down until the glide to the flare is the steepest allowed."""
    items = [
        item(0, d.MAV_CMD_NAV_LOITER_TO_ALT, CENTRE, z=50.0, p1=1.0, p2=RADIUS),
        item(1, d.MAV_CMD_NAV_LAND, LAND, z=0.0),
    ]
    ex = executor(items, pos=(-250.0, -900.0), alt=HOME_ALT + 50.0)
    ex.config.final_slope_max = math.radians(2.0)
    ex.config.final_flare = (100.0, 5.0)
    low = HOME_ALT + 5.0 + 700.0 * math.tan(math.radians(2.0))
    sp = ex.step((-250.0, -900.0), HOME_ALT + 50.0, 0.0)
    assert sp.kind == Kind.CIRCLE and sp.alt_msl == pytest.approx(low, abs=0.1)


def test_a_landing_circle_flown_wider_or_lower_than_planned_is_said_once():
    """QGroundControl draws the plan's circle and height: the operator is told, once, what
    is flown instead (QGroundControl 5 showed a 75 m circle at 40 m; the C172 flew 230 m
    at 33 m for a final no steeper than 5°), and nothing for a circle flown as planned."""
    items = [
        item(0, d.MAV_CMD_NAV_LOITER_TO_ALT, (-75.0, -380.0), z=40.0, p1=1.0, p2=75.0),
        item(1, d.MAV_CMD_NAV_LAND, (0.0, 0.0), z=0.0),
    ]
    ex = executor(items, pos=(-75.0, -900.0), alt=HOME_ALT + 40.0)
    ex.config.final_slope_max = math.radians(5.0)
    for _ in range(3):
        ex.step((-75.0, -900.0), HOME_ALT + 40.0, 0.0, turn_radius=230.0)
    assert ex.said == [(d.MAV_SEVERITY_NOTICE, "Land circle: 230 m at 33 m (plan: 75 m at 40 m)")]
    assert all(len(text) <= 50 for _, text in ex.said)  # one STATUSTEXT
    as_planned = executor(items, pos=(-75.0, -900.0), alt=HOME_ALT + 40.0)
    as_planned.step((-75.0, -900.0), HOME_ALT + 40.0, 0.0, turn_radius=60.0)
    assert as_planned.said == []
    # Nor for a few metres: a 250 m circle flown 253 m wide (the c172p's turn on land_east).
    near = executor([item(0, d.MAV_CMD_NAV_LOITER_TO_ALT, CENTRE, z=50.0, p1=1.0, p2=RADIUS),
                     item(1, d.MAV_CMD_NAV_LAND, LAND, z=0.0)], pos=(-250.0, -900.0),
                    alt=HOME_ALT + 50.0)  # fmt: skip
    near.step((-250.0, -900.0), HOME_ALT + 50.0, 0.0, turn_radius=253.0)
    assert near.said == []


def test_a_landing_circle_met_at_its_exit_point_is_flown_round_before_the_final():
    """Down at the circle's height on the way there, the aircraft meets the circle at its
    exit point flying across it (south, the final runs east): it turns final only once it
    has flown round the circle, not at once 90° off the runway."""
    items = [
        item(0, d.MAV_CMD_NAV_LOITER_TO_ALT, CENTRE, z=50.0, p1=1.0, p2=RADIUS),
        item(1, d.MAV_CMD_NAV_LAND, LAND, z=0.0),
    ]
    ex = executor(items, pos=(300.0, -500.0), alt=HOME_ALT + 50.0)
    for north in range(300, -60, -10):  # across the northern point (the exit) southwards
        assert ex.step((float(north), -500.0), HOME_ALT + 50.0, 0.0).kind == Kind.CIRCLE
    kinds = [ex.step(on_circle(CENTRE, RADIUS, deg), HOME_ALT + 50.0, 0.0).kind
             for deg in range(100, 400, 5)]  # fmt: skip
    assert Kind.LAND in kinds  # round the circle and out at its northern point (360°)


def test_a_waypoint_before_the_final_reached_too_high_is_circled_down_first():
    """The approach waypoint 800 m before the point at 30 m, reached at 60 m: the final
    would start 30 m above its path. The aircraft circles down on a circle through the
    waypoint, tangent to the final and on its own side (north), then turns final there."""
    wp_ne = (0.0, -500.0)
    items = [
        item(0, d.MAV_CMD_NAV_WAYPOINT, wp_ne, z=30.0),
        item(1, d.MAV_CMD_NAV_LAND, LAND, z=0.0),
    ]
    ex = executor(items, pos=(100.0, -1500.0), alt=HOME_ALT + 60.0)
    sp = ex.step((10.0, -510.0), HOME_ALT + 60.0, 0.0, turn_radius=150.0)
    assert sp.kind == Kind.CIRCLE and sp.alt_msl == pytest.approx(HOME_ALT + 30.0)
    assert sp.b == pytest.approx((150.0, -500.0), abs=0.5) and sp.radius == pytest.approx(150.0)
    assert not sp.clockwise  # north of an eastward final: left turns bring it back onto it
    for deg in range(180, -400, -5):  # round it, down at the height
        sp = ex.step(on_circle(sp.b, 150.0, deg), HOME_ALT + 30.0, 0.0, 150.0)
        if sp.kind == Kind.LAND:
            break
    assert sp.kind == Kind.LAND and sp.a == pytest.approx(wp_ne, abs=0.5)
    assert sp.from_alt == pytest.approx(HOME_ALT + 30.0)
