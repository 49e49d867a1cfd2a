"""One thing on an output: the camera's shutter, the gripper and the actuator sets each
refuse an output another of them is set up on, as they refuse a surface's, and say which
(an ArduPilot or PX4 output has one function). A light wired as actuator set 1 on the
gripper's output would otherwise drop the payload when it is switched on.

The payloads are the flight controller's own, wired as its plug-in wires them
(``configure_payloads``)."""

from __future__ import annotations

from companion.control.mission.actuator_sets import ACTUATOR_PARAMS, ActuatorSets
from companion.control.mission.camera import CAMERA_PARAMS
from companion.control.mission.camera_shots import CameraPorts, CameraShots
from companion.control.mission.gripper import GRIPPER_PARAMS, Gripper
from companion.control.mission.servo_payload import configure_payloads
from companion.messages import GpsFix, VehicleCommand
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import HOME_ALT

SURFACES = {1: "aileron", 2: "elevator", 3: "rudder", 4: "throttle", 5: "flaps", 6: "brakes"}
PHOTO = (d.MAV_CMD_DO_DIGICAM_CONTROL, (0.0, 0.0, 0.0, 1.0))  # the photo button: param1-3, 5
DEFAULTS = {p.name: p.default for p in (*CAMERA_PARAMS, *GRIPPER_PARAMS, *ACTUATOR_PARAMS)}


class Payloads:
    """The camera, the gripper and the actuator sets on one servo card, configured from
    ``params`` over the shipped defaults; what they sent and said."""

    def __init__(self, **params: float) -> None:
        self.sent: list[VehicleCommand] = []
        self.said: list[str] = []
        say = lambda _t, _severity, text: self.said.append(text)  # noqa: E731
        ports = CameraPorts(lambda _c: None, self.sent.append, say,
                            lambda: GpsFix(), lambda: HOME_ALT)  # fmt: skip
        self.camera = CameraShots(ports, SURFACES)
        self.gripper = Gripper(self.sent.append, say, SURFACES)
        self.actuators = ActuatorSets(self.sent.append, say, SURFACES)
        payloads = (self.camera, self.gripper, self.actuators)
        configure_payloads(payloads, {**DEFAULTS, **params}, SURFACES)


def test_a_set_wired_to_the_set_up_grippers_output_is_refused_naming_the_gripper():
    p = Payloads(GRIP_ENABLE=1.0, GRIP_OUTPUT=8.0, ACT_SET1_OUT=8.0)
    assert p.actuators.act(10, [1.0] + [float("nan")] * 5, 0) == (
        "Set actuator: ACT_SET1_OUT 8 drives the gripper"
    )
    assert p.gripper.act(20, 0) == "Gripper: GRIP_OUTPUT 8 drives the actuator set 1"
    assert p.sent == []  # nothing moved: the payload still held


def test_the_camera_and_the_gripper_on_one_output_refuse_each_other():
    p = Payloads(CAM1_TYPE=1.0, CAM1_OUTPUT=7.0, GRIP_ENABLE=1.0, GRIP_OUTPUT=7.0)
    assert p.gripper.act(10, 1) == "Gripper: GRIP_OUTPUT 7 drives the camera"
    assert p.camera.command(*PHOTO) == "Camera: output 7 drives the gripper"
    assert p.sent == []


def test_a_payload_not_set_up_claims_no_output_and_a_surface_is_still_named_first():
    # As shipped the gripper (output 8) and the camera (output 7) are not set up: a set on
    # either output works, and one on the elevator's is refused naming the elevator.
    p = Payloads(ACT_SET1_OUT=8.0, ACT_SET2_OUT=7.0, ACT_SET3_OUT=2.0)
    assert p.actuators.act(10, [1.0, -1.0] + [float("nan")] * 4, 0) is None
    assert [(round(c.param[0]), round(c.param[1])) for c in p.sent] == [(8, 2000), (7, 1000)]
    refused = p.actuators.act(20, [float("nan")] * 2 + [0.0] + [float("nan")] * 3, 0)
    assert refused == "Set actuator: ACT_SET3_OUT 2 drives the elevator"


def test_each_on_an_output_of_its_own_works_as_before():
    p = Payloads(CAM1_TYPE=1.0, CAM1_OUTPUT=7.0, GRIP_ENABLE=1.0, GRIP_OUTPUT=8.0)
    assert p.gripper.act(10, 1) is None
    assert p.camera.command(*PHOTO) is None
    assert [(round(c.param[0]), round(c.param[1])) for c in p.sent] == [(8, 1900)]
