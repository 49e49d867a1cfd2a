"""The controller plug-in's camera: a photo becomes two DO_SET_SERVO pulses for the servo
output and one CameraCapture with where the aircraft was; a camera that is not set up, or
wired to a surface's output, takes none and the operator is told once why."""

from __future__ import annotations

from companion.control.mission.camera import CAMERA_PARAMS
from companion.control.mission.camera_shots import CameraPorts, CameraShots
from companion.messages import CommandId, GpsFix, NavState
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import HOME_ALT, item

SURFACES = {1: "aileron", 2: "elevator"}
SERVO_CAMERA = {p.name: p.default for p in CAMERA_PARAMS} | {"CAM1_TYPE": 1.0}


class Recorder:
    """The plug-in's side: what the camera published and said."""

    def __init__(self) -> None:
        self.captures, self.commands, self.texts = [], [], []
        self.fix = GpsFix(t_us=9_900_000, utc_us=1_767_225_600_000_000)

    def ports(self) -> CameraPorts:
        return CameraPorts(
            self.captures.append, self.commands.append,
            lambda _t, severity, text: self.texts.append((severity, text)),
            lambda: self.fix, lambda: HOME_ALT,
        )  # fmt: skip


def nav_at(t_s: float) -> NavState:
    nav = NavState(t_us=round(t_s * 1e6), lat_deg=-37.9, lon_deg=145.1)
    nav.alt_msl_m = HOME_ALT + 80.0
    nav.q[:] = [1.0, 0.0, 0.0, 0.0]
    return nav


def fly(shots: CameraShots, items: list, seconds: float) -> None:
    for k in range(round(seconds / 0.02)):
        shots.step(nav_at(10.0 + k * 0.02), items if k == 0 else [], (25.0 * k * 0.02, 0.0))


def test_a_photo_is_a_pulse_pair_for_the_servo_output_and_a_capture_with_its_place():
    rec = Recorder()
    shots = CameraShots(rec.ports(), SURFACES)
    shots.configure(SERVO_CAMERA)
    fly(shots, [item(0, d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, p1=100.0, p3=1.0)], 4.3)
    assert [c.seq for c in rec.captures] == [0, 1]  # from 0, as PX4 numbers them
    first = rec.captures[0]
    assert (first.lat, first.lon, first.alt) == (-37.9, 145.1, HOME_ALT + 80.0)
    assert first.ground_distance == 80.0 and list(first.q) == [1.0, 0.0, 0.0, 0.0]
    # The newest fix was 0.1 s before the photo: its UTC moved on by 0.1 s.
    assert first.timestamp_utc == rec.fix.utc_us + 100_000 and first.result == 1
    pulses = [(c.command, c.param[0], c.param[1]) for c in rec.commands]
    servo = int(CommandId.SET_SERVO)
    assert pulses == [(servo, 7, 1300), (servo, 7, 1100)] * 2
    assert rec.texts == []


def test_a_camera_not_set_up_takes_no_photo_and_says_so_once():
    rec = Recorder()
    shots = CameraShots(rec.ports(), SURFACES)
    shots.configure({})  # CAM1_TYPE's default: None
    fly(shots, [item(0, d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, p1=50.0, p3=1.0)], 3.0)
    fly(shots, [item(1, d.MAV_CMD_DO_DIGICAM_CONTROL)], 1.0)
    assert rec.captures == [] and rec.commands == []
    assert rec.texts == [(d.MAV_SEVERITY_WARNING, "Camera: CAM1_TYPE is None: no photos")]


def test_a_stop_item_with_no_camera_says_nothing():
    rec = Recorder()
    shots = CameraShots(rec.ports(), SURFACES)
    shots.configure({})  # no camera, and a landing pattern's camera stops
    stops = [item(0, d.MAV_CMD_DO_SET_CAM_TRIGG_DIST), item(1, d.MAV_CMD_IMAGE_STOP_CAPTURE)]
    fly(shots, stops, 1.0)
    assert rec.texts == [] and rec.commands == []


def test_a_ground_stations_photo_button_takes_one_or_says_why_not():
    rec = Recorder()
    shots = CameraShots(rec.ports(), SURFACES)
    button = (d.MAV_CMD_DO_DIGICAM_CONTROL, (0.0, 0.0, 0.0, 1.0))  # param1, 2, 3, 5
    assert shots.command(*button) == "Camera: CAM1_TYPE is None: no photos"
    shots.configure(SERVO_CAMERA)
    assert shots.command(*button) is None
    fly(shots, [], 1.0)
    assert [c.seq for c in rec.captures] == [0]


def test_a_shutter_on_a_surfaces_output_is_refused_with_the_reason():
    rec = Recorder()
    shots = CameraShots(rec.ports(), SURFACES)
    shots.configure(SERVO_CAMERA | {"CAM1_OUTPUT": 2.0})
    fly(shots, [item(0, d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, p1=50.0, p3=1.0)], 3.0)
    assert rec.captures == [] and rec.commands == []
    assert rec.texts == [(d.MAV_SEVERITY_WARNING, "Camera: output 2 drives the elevator")]
