"""``companion mission save`` writes all the vehicle stored: mission, geofence, rally points.

Through the real command line: load a plan, save it, clear the store, load the saved file;
the stored lists are byte for byte the same, and the saved file is laid out as
QGroundControl 4.4 writes a plan (``geoFence`` polygons and circles with their inclusion
flags and versions, ``breachReturn``, ``rallyPoints``).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from companion.control.mission.mission_files import MissionStore
from mavlink_dialect import companion as d
from tests.support.configs import vehicle_config
from tests.support.vehicle import REPO

SQUARE = REPO / "qgc_plans" / "square.plan"
INCLUDE = [[-37.9168066, 145.1260399], [-37.8933821, 145.1260399], [-37.8933821, 145.1624288]]
EXCLUDE = [[-37.905, 145.14], [-37.904, 145.14], [-37.904, 145.141], [-37.905, 145.141]]
GEOFENCE = {
    "version": 2,
    "polygons": [
        {"inclusion": True, "version": 1, "polygon": INCLUDE},
        {"inclusion": False, "version": 1, "polygon": EXCLUDE},
    ],
    "circles": [
        {"inclusion": True, "version": 1, "circle": {"center": [-37.905, 145.144], "radius": 2500}},
        {"inclusion": False, "version": 1, "circle": {"center": [-37.9, 145.15], "radius": 120.5}},
    ],
    "breachReturn": [-37.9114, 145.1442, 90],
}
RALLY = {"version": 2, "points": [[-37.9114009, 145.1442344, 80], [-37.8999, 145.15, 120.5]]}
STORED = ("mission.json", "fence.json", "rally.json")


def _fenced_plan(tmp_path: Path) -> Path:
    plan = json.loads(SQUARE.read_text())
    plan["geoFence"], plan["rallyPoints"] = GEOFENCE, RALLY
    path = tmp_path / "fenced.plan"
    path.write_text(json.dumps(plan, indent=4))
    return path


def _mission(*args: object) -> str:
    done = subprocess.run(
        [sys.executable, "-m", "companion", "mission", *map(str, args)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    return " ".join(done.stdout.split())  # rich wraps long lines at the terminal width


def _stored(state: Path) -> dict[str, str]:
    return {name: (state / "missions" / name).read_text() for name in STORED}


@pytest.fixture
def config(tmp_path):
    path = tmp_path / "v.toml"
    path.write_text(vehicle_config("plan-save", state_dir=tmp_path / "state"))
    return path


def test_fence_circles_and_rally_points_survive_load_save_load(tmp_path, config):
    said = _mission("load", _fenced_plan(tmp_path), "-c", config)
    assert "stored 6 mission, 10 fence, 2 rally items" in said
    stored = _stored(tmp_path / "state")
    saved = tmp_path / "saved.plan"
    said = _mission("save", saved, "-c", config)
    assert "wrote 6 mission, 10 fence, 2 rally items" in said

    shutil.rmtree(tmp_path / "state" / "missions")  # the vehicle's store, cleared
    assert "stored 6 mission, 10 fence, 2 rally items" in _mission("load", saved, "-c", config)
    assert _stored(tmp_path / "state") == stored


def test_saved_plan_has_the_fence_and_rally_sections_qgroundcontrol_reads(tmp_path, config):
    _mission("load", _fenced_plan(tmp_path), "-c", config)
    _mission("save", tmp_path / "saved.plan", "-c", config)
    plan = json.loads((tmp_path / "saved.plan").read_text())
    assert plan["fileType"] == "Plan" and plan["version"] == 1
    assert plan["geoFence"] == GEOFENCE  # the same keys, versions and values QGC wrote
    assert plan["rallyPoints"] == RALLY


def test_square_plan_saves_its_fence(tmp_path, config):
    _mission("load", SQUARE, "-c", config)
    said = _mission("save", tmp_path / "saved.plan", "-c", config)
    assert "wrote 6 mission, 4 fence, 1 rally items" in said
    plan = json.loads((tmp_path / "saved.plan").read_text())
    assert plan["geoFence"] == json.loads(SQUARE.read_text())["geoFence"]
    assert "breachReturn" not in plan["geoFence"]  # none stored: none written


def test_a_rally_point_stored_above_sea_level_keeps_its_altitude_through_save_and_load(
    tmp_path, config
):
    """A .plan's rally altitudes are above home: one uploaded above sea level is saved with
    its frame (a key QGroundControl passes over) and loads back the same, not as 180 m
    above home."""
    _mission("load", SQUARE, "-c", config)
    store = MissionStore(tmp_path / "state" / "missions")
    relative = store.items[d.MAV_MISSION_TYPE_RALLY][0]
    store.replace(
        d.MAV_MISSION_TYPE_RALLY, [replace(relative, frame=d.MAV_FRAME_GLOBAL_INT, z=180.0)]
    )
    stored = _stored(tmp_path / "state")
    saved = tmp_path / "saved.plan"
    _mission("save", saved, "-c", config)
    rally = json.loads(saved.read_text())["rallyPoints"]
    assert rally["points"] == [[-37.9114009, 145.1442344, 180.0]]
    assert rally["companionFrames"] == [d.MAV_FRAME_GLOBAL_INT]
    shutil.rmtree(tmp_path / "state" / "missions")
    _mission("load", saved, "-c", config)
    assert _stored(tmp_path / "state") == stored
