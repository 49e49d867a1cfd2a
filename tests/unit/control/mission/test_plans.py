"""QGroundControl .plan files: every shipped plan imports, validates and round-trips."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from companion.control.mission.items import MissionItem, check_mission
from companion.control.mission.plan import PlanError, load_plan, save_plan
from mavlink_dialect import companion as d
from tests.support.configs import vehicle_config
from tests.support.vehicle import REPO

PLANS = sorted((REPO / "qgc_plans").glob("*.plan"))


@pytest.mark.parametrize("path", PLANS, ids=[p.stem for p in PLANS])
def test_every_shipped_plan_imports_and_the_vehicle_can_fly_it(path):
    lists = load_plan(path)
    assert lists[0], "a mission"
    assert all(check_mission(items) == d.MAV_MISSION_ACCEPTED for items in lists.values())
    raw = json.loads(path.read_text())
    assert "geoFence" in raw and "rallyPoints" in raw  # MAVSDK's importer needs both


def test_square_plan_contents():
    lists = load_plan(REPO / "qgc_plans" / "square.plan")
    takeoff, *legs, rtl = lists[0]
    assert takeoff.command == d.MAV_CMD_NAV_TAKEOFF and takeoff.z == 100.0
    assert [leg.command for leg in legs] == [d.MAV_CMD_NAV_WAYPOINT] * 4
    assert rtl.command == d.MAV_CMD_NAV_RETURN_TO_LAUNCH
    assert len(lists[1]) == 4 and len(lists[2]) == 1


def test_do_jump_targets_become_sequence_numbers_and_round_trip(tmp_path):
    lists = load_plan(REPO / "qgc_plans" / "jump.plan")
    jump = next(i for i in lists[0] if i.command == d.MAV_CMD_DO_JUMP)
    assert jump.param1 == 1.0  # doJumpId 2 is the second item, seq 1
    out = tmp_path / "again.plan"
    save_plan(out, lists)
    again = load_plan(out)
    assert [(i.command, i.x, i.y, i.param1) for i in again[0]] == [
        (i.command, i.x, i.y, i.param1) for i in lists[0]
    ]


def test_bad_plans_are_refused_with_the_reason(tmp_path):
    bad = tmp_path / "bad.plan"
    bad.write_text(
        '{"fileType": "Plan", "mission": {"items": [{"type": "ComplexItem", '
        '"complexItemType": "survey"}]}}'
    )
    with pytest.raises(PlanError, match="item 0: survey items are not supported"):
        load_plan(bad)
    bad.write_text("{not json")
    with pytest.raises(PlanError, match="not a readable plan"):
        load_plan(bad)


def test_cli_load_and_save(tmp_path):
    config = tmp_path / "v.toml"
    config.write_text(vehicle_config("m", state_dir=tmp_path / "state"))
    run = [sys.executable, "-m", "companion", "mission"]
    done = subprocess.run(
        [*run, "load", str(PLANS[0]), "-c", str(config)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    saved = tmp_path / "out.plan"
    done = subprocess.run(
        [*run, "save", str(saved), "-c", str(config)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0 and len(load_plan(saved)[0]) == len(load_plan(PLANS[0])[0])
    assert Path(tmp_path / "state" / "missions" / "mission.json").exists()


def test_a_fence_uploaded_over_mavlink_is_saved_polygon_by_polygon(tmp_path):
    """A ground station uploads fence items in its own order and frame: the saved plan
    groups the vertices by the count each carries, as the vehicle's fence reads them."""
    incl, excl = d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION, d.MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION
    square = [(-379000000, 1451000000), (-378900000, 1451000000), (-378900000, 1451100000)]
    triangle = [(-379500000, 1452000000), (-379400000, 1452000000), (-379400000, 1452100000)]
    points = [*square, (-379100000, 1451500000), *triangle]
    commands = [incl] * 3 + [excl] + [d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_EXCLUSION] * 3
    fence = [
        MissionItem(
            s, d.MAV_FRAME_GLOBAL, cmd, 0, 1, 75.0 if cmd == excl else 3.0, 0, 0, 0, x, y, 0
        )
        for s, (cmd, (x, y)) in enumerate(zip(commands, points, strict=True))
    ]
    assert save_plan(tmp_path / "f.plan", {0: [], 1: fence, 2: []}) == {0: 0, 1: 7, 2: 0}
    saved = json.loads((tmp_path / "f.plan").read_text())["geoFence"]
    assert [(p["inclusion"], len(p["polygon"])) for p in saved["polygons"]] == [
        (True, 3),
        (False, 3),
    ]
    assert saved["circles"] == [
        {"inclusion": False, "version": 1, "circle": {"center": [-37.91, 145.15], "radius": 75.0}}
    ]
    again = load_plan(tmp_path / "f.plan")[1]
    assert sorted((i.command, i.x, i.y, i.param1) for i in again) == sorted(
        (i.command, i.x, i.y, i.param1) for i in fence
    )
