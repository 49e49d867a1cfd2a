"""A camera's shutter on a servo output, worked as a QGroundControl survey asks: photos a
distance apart along the flight, at intervals, or one at a time; each a pulse of
CAM1_DURATION at CAM1_SERVO_ON, then CAM1_SERVO_OFF; never two closer than
CAM1_INTRVAL_MIN; and the items QGroundControl writes are checked at upload."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import pytest

from companion.control.mission.camera import CameraConfig, CameraTrigger
from companion.control.mission.items import check_item
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import HOME_ALT, cruising, executor, item, wp

SERVO = CameraConfig(servo=True, output=7, on_us=1900, off_us=1100, duration_s=0.1)
STEP_S, SPEED = 0.02, 25.0  # the controller's 50 Hz, a c172p's cruise


def fly(trigger: CameraTrigger, seconds: float, start_s: float = 0.0):
    """Fly north at SPEED for ``seconds``: each photo's (time, north) and every pulse's
    (time, output, µs)."""
    photos, pulses = [], []
    for k in range(round(seconds / STEP_S)):
        t = start_s + k * STEP_S
        step = trigger.step(t, (SPEED * t, 0.0))
        if step.photo:
            photos.append((t, SPEED * t))
        pulses += [(t, output, us) for output, us in step.pulses]
    return photos, pulses


def distance(metres: float, now: bool = True):
    return d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, (metres, 0.0, 1.0 if now else 0.0)


def test_a_survey_distance_takes_a_photo_every_so_many_metres_flown():
    trigger = CameraTrigger(SERVO)
    trigger.apply(*distance(50.0))
    photos, _ = fly(trigger, 20.0)  # 500 m
    norths = [n for _, n in photos]
    assert norths[0] == 0.0  # the first at once (param3 1)
    assert len(norths) == 10 and trigger.taken == 10 and trigger.seq == 9
    gaps = [b - a for a, b in itertools.pairwise(norths)]
    assert all(50.0 <= g <= 50.0 + SPEED * STEP_S for g in gaps), gaps


def test_without_trigger_now_the_first_photo_comes_one_distance_on():
    trigger = CameraTrigger(SERVO)
    trigger.apply(*distance(100.0, now=False))
    photos, _ = fly(trigger, 10.0)
    assert [round(n) for _, n in photos] == [100, 200]


def test_each_photo_is_a_pulse_held_for_the_duration_then_released():
    trigger = CameraTrigger(SERVO)
    trigger.apply(*distance(100.0))
    photos, pulses = fly(trigger, 9.0)
    assert len(photos) == 3
    ons = [t for t, out, us in pulses if (out, us) == (7, 1900)]
    offs = [t for t, out, us in pulses if (out, us) == (7, 1100)]
    assert ons == [t for t, _ in photos]
    assert [round(off - on, 3) for on, off in zip(ons, offs, strict=True)] == [0.1] * 3


def test_photos_never_come_closer_than_the_cameras_shortest_interval():
    slow = CameraConfig(servo=True, output=7, on_us=1900, off_us=1100, min_interval_s=1.0)
    trigger = CameraTrigger(slow)
    trigger.apply(*distance(10.0))  # every 0.4 s at 25 m/s: too fast for this camera
    photos, _ = fly(trigger, 10.0)
    times = [t for t, _ in photos]
    assert all(b - a >= 1.0 - 1e-9 for a, b in itertools.pairwise(times))
    assert len(times) == 10  # each as soon as the camera can


def test_an_idle_camera_says_so_and_a_busy_one_until_its_shutter_is_released():
    trigger = CameraTrigger(SERVO)
    assert not trigger.busy
    trigger.apply(d.MAV_CMD_DO_DIGICAM_CONTROL, (0.0, 0.0, 0.0, 0.0, 1.0))
    assert trigger.busy
    assert trigger.step(0.0, (0.0, 0.0)).photo and trigger.busy  # the shutter held
    assert trigger.step(0.1, (0.0, 0.0)).pulses == [(7, 1100)] and not trigger.busy


def test_a_stop_item_ends_the_photos_and_a_distance_of_zero_too():
    for stop in ((d.MAV_CMD_IMAGE_STOP_CAPTURE, ()), distance(0.0)):
        trigger = CameraTrigger(SERVO)
        trigger.apply(*distance(50.0))
        fly(trigger, 5.0)
        taken = trigger.taken
        trigger.apply(*stop)
        photos, _ = fly(trigger, 10.0, start_s=5.0)
        assert photos == [] and trigger.taken == taken


def test_image_capture_takes_its_count_at_its_interval_or_one_photo():
    trigger = CameraTrigger(SERVO)
    trigger.apply(d.MAV_CMD_IMAGE_START_CAPTURE, (0.0, 2.0, 3.0))
    photos, _ = fly(trigger, 12.0)
    assert [round(t, 2) for t, _ in photos] == [0.0, 2.0, 4.0]
    trigger = CameraTrigger(SERVO)
    trigger.apply(d.MAV_CMD_IMAGE_START_CAPTURE, (0.0, 0.0, 1.0))  # "Take photo"
    assert len(fly(trigger, 5.0)[0]) == 1


def test_digicam_control_takes_one_photo_from_a_mission_item_too():
    trigger = CameraTrigger(SERVO)
    trigger.apply(d.MAV_CMD_DO_DIGICAM_CONTROL, (0.0, 0.0, 0.0, 0.0, 1.0))
    assert len(fly(trigger, 3.0)[0]) == 1
    shoot = item(0, d.MAV_CMD_DO_DIGICAM_CONTROL)
    trigger.apply_item(shoot)  # param5 0: no photo
    assert fly(trigger, 3.0)[0] == []
    trigger.apply_item(replace(shoot, x=1))  # param5 travels in MISSION_ITEM_INT's x
    assert len(fly(trigger, 3.0)[0]) == 1


def test_what_qgroundcontrol_writes_is_accepted_and_nonsense_refused_at_upload():
    assert check_item(item(0, d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, p1=25.0, p3=1.0), 1) == 0
    assert check_item(item(0, d.MAV_CMD_IMAGE_START_CAPTURE, p3=1.0), 1) == 0
    assert check_item(item(0, d.MAV_CMD_IMAGE_STOP_CAPTURE), 1) == 0
    for bad in (-1.0, math.nan, math.inf):
        refused = check_item(item(0, d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, p1=bad), 1)
        assert refused == d.MAV_MISSION_INVALID_PARAM1, bad
    for p2, p3, result in ((-1.0, 1.0, 2), (1.0, 1.5, 3), (1.0, -2.0, 3), (math.nan, 1.0, 2)):
        refused = check_item(item(0, d.MAV_CMD_IMAGE_START_CAPTURE, p2=p2, p3=p3), 1)
        assert refused == getattr(d, f"MAV_MISSION_INVALID_PARAM{result}"), (p2, p3)


def test_the_executor_hands_camera_items_out_once_as_it_passes_them():
    shoot = item(1, d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, p1=40.0, p3=1.0)
    ex = executor([wp(0, (0.0, 1000.0)), shoot, wp(2, (1000.0, 1000.0))])
    ex.step((0.0, 10.0), HOME_ALT + 100.0, 0.0)
    assert ex.take_actions() == ([], [])
    ex.step((0.0, 1000.0), HOME_ALT + 100.0, 1.0)
    assert ex.take_actions() == ([], [shoot]) and ex.current == 2
    assert ex.take_actions() == ([], [])


def test_the_controller_passes_them_on_in_one_step_only():
    shoot = item(1, d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, p1=40.0, p3=1.0)
    controller, nav, status = cruising([wp(0, (0.0, 30.0)), shoot, wp(2, (0.0, 2000.0))])
    passed = [controller.step(nav, status, k * 0.02).passed_items for k in range(5)]
    assert [p for p in passed if p] == [[shoot]]
    assert pytest.approx(controller.home_alt) == HOME_ALT
