"""A survey's photos, flown in lockstep JSBSim with the c172p: the camera's shutter on the
Mini SSC's spare output 7 (CAM1_TYPE Servo), a photo every 50 m along a leg as
QGroundControl's survey asks for it (DO_SET_CAM_TRIGG_DIST 50 with "trigger now" at the
leg's start, 0 at its end). Each photo reaches the ground station as CAMERA_TRIGGER and
the flight log as PX4's camera_capture, which QGroundControl's GeoTag Images reads."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import pytest
from pyulog import ULog

from companion.actuators.minissc import position_for_pulse
from companion.geodesy import LocalFrame
from mavlink_dialect import companion as d
from tests.support.geotag import camera_feedback, images_tagged
from tests.support.vehicle import REPO, set_param

PLAN = REPO / "qgc_plans" / "short_leg.plan"
SPACING_M = 50.0
LEG_M = 1598.0  # short_leg.plan's second leg, east waypoint to north waypoint, straight
pytestmark = pytest.mark.vehicle(airframe="c172p")


def _survey(tmp_path: Path) -> Path:
    """short_leg.plan with photos every SPACING_M on its second leg, as a survey's
    transect: the distance set (and a photo at once) as the leg starts, 0 as it ends."""
    plan = json.loads(PLAN.read_text())
    items = plan["mission"]["items"]

    def camera(metres: float, now: int) -> dict:
        return {"type": "SimpleItem", "command": d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, "frame": 2,
                "autoContinue": True, "params": [metres, 0, now, 0, 0, 0, 0]}  # fmt: skip

    items.insert(2, camera(SPACING_M, 1))
    items.insert(4, camera(0.0, 0))
    for n, item in enumerate(items, start=1):
        item["doJumpId"] = n
    path = tmp_path / "survey.plan"
    path.write_text(json.dumps(plan))
    return path


def _photos_until(sim, done) -> list:
    """Every CAMERA_TRIGGER until ``done(msg)``."""
    photos = []

    def note(m):
        if m.get_type() == "CAMERA_TRIGGER":
            photos.append(m)
        return done(m)

    sim.watcher.until(note, 600, "the flight's end of the survey")
    return photos


def _photo_button(sim, said: str = "", seen: list | None = None) -> int:
    """QGroundControl's simple camera control: DO_DIGICAM_CONTROL with param5 1; its
    COMMAND_ACK's result (with ``said``, the reason it comes with too). The photo's
    CAMERA_TRIGGER may come before the ack: those seen meanwhile go into ``seen``."""
    w = sim.watcher
    before = len(w.texts)
    w.mav.command_long_send(1, 1, d.MAV_CMD_DO_DIGICAM_CONTROL, 0, 0, 0, 0, 0, 1, 0, 0)

    def acked(m):
        if m.get_type() == "CAMERA_TRIGGER" and seen is not None:
            seen.append(m)
        return m.get_type() == "COMMAND_ACK" and m.command == d.MAV_CMD_DO_DIGICAM_CONTROL and m

    result = w.until(acked, 30, "DO_DIGICAM_CONTROL's ack").result
    if said:
        w.until(lambda _m: any(said in t for t in w.texts[before:]) or None, 30, repr(said))
    return result


COMPOSED = REPO / "companion" / "configs" / "sim_composed.toml"


@pytest.mark.timeout(900)
@pytest.mark.parametrize(
    "sim",
    [{}, {"sim_args": ["--config", str(COMPOSED)]}],
    ids=["one_process_per_plugin", "composed"],
    indirect=True,
)
def test_a_survey_leg_is_photographed_every_50_m_and_each_photo_logged_for_geotagging(
    sim, tmp_path
):
    sim.wait_ready()
    said = "Camera: photos only while armed"  # QGroundControl's photo button, disarmed
    assert _photo_button(sim, said) == d.MAV_RESULT_DENIED
    set_param(sim.watcher, "CAM1_TYPE", 1.0)
    set_param(sim.watcher, "CAM1_OUTPUT", 7.0)
    sim.upload_plan(_survey(tmp_path))
    sim.arm_and_start()
    leg_end = 3  # the waypoint ending the survey's leg; the stop item follows it
    photos = _photos_until(sim, lambda m: m.get_type() == "MISSION_ITEM_REACHED"
                           and m.seq >= leg_end)  # fmt: skip
    # The link may send the leg's last photo after the item reached (it tells a reached
    # item at once, a photo on its next turn): a simulated second more is the leg's.
    w = sim.watcher
    grace_s = w.time_boot_s + 1.0
    photos += _photos_until(sim, lambda _m: w.time_boot_s >= grace_s)
    seqs = [p.seq for p in photos]
    assert seqs == list(range(len(seqs))), seqs  # from 0, as PX4 numbers them
    # A photo for every 50 m of the leg at least: the turn onto it is flown too (the gaps
    # below are the photos' own spacing along the track).
    assert len(seqs) >= LEG_M // SPACING_M, len(seqs)
    end_s = w.time_boot_s + 30.0  # half a minute on, circling the last waypoint
    later = _photos_until(sim, lambda _m: w.time_boot_s >= end_s)
    assert later == []  # the stop item passed: no more photos
    button: list = []
    assert _photo_button(sim, seen=button) == d.MAV_RESULT_ACCEPTED
    end_s = w.time_boot_s + 5.0
    button += _photos_until(sim, lambda _m: w.time_boot_s >= end_s)
    assert [p.seq for p in button] == [len(seqs)]  # one photo, numbered on
    seqs.append(len(seqs))
    log = sim.disarm(force=True)[-1]
    ulog = ULog(str(log))
    capture = ulog.get_dataset("camera_capture").data
    assert list(capture["seq"]) == seqs and set(capture["result"]) == {1}
    # QGroundControl 4.4's GeoTag Images finds the same photos in the same places.
    tags = camera_feedback(log)
    assert [t["seq"] for t in tags] == seqs
    # One picture a photo: each tagged with its own photo's place, none left out.
    assert images_tagged(tags, len(seqs)) == [(i, i) for i in range(len(seqs))]
    places = list(zip(capture["lat"], capture["lon"], strict=True))
    assert [(t["lat"], t["lon"]) for t in tags] == places
    frame = LocalFrame(*places[0])
    where = [frame.ne(lat, lon) for lat, lon in places]
    gaps = [math.dist(a, b) for a, b in itertools.pairwise(where[:-1])]  # the leg's
    assert all(SPACING_M - 1.0 <= g <= SPACING_M + 3.0 for g in gaps), gaps
    heights = capture["ground_distance"]
    assert all(70.0 <= h <= 90.0 for h in heights), heights  # the plan's 80 m
    utc, t = capture["timestamp_utc"].astype(int), capture["timestamp"].astype(int)
    assert all(utc > 0)  # the GPS's time: the photos' files can be matched by their clocks
    # Each photo's UTC is the newest fix's moved on by the vehicle's clock: right to the
    # jitter with which fixes arrive (a few tens of milliseconds), plenty for matching
    # pictures whose own clocks count whole seconds.
    assert all(abs((u - utc[0]) - (v - t[0])) < 250_000 for u, v in zip(utc, t, strict=True))
    # Each photo a pulse on output 7 (the card's servo 6): pressed, then released.
    servos = ulog.get_dataset("actuators_servos").data["position[6]"]
    pressed, released = position_for_pulse(1300), position_for_pulse(1100)
    moves = [b for a, b in itertools.pairwise(servos) if a != b]
    assert moves.count(pressed) == len(seqs) and moves.count(released) == len(seqs)
