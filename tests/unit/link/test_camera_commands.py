"""The camera's commands at the link, as QGroundControl's photo button and scripts send
them: refused with the reason while the flight controller is not running (disarmed),
otherwise handed to it (its ack answers); broken parameters refused by the rules."""

from __future__ import annotations

import math

import pytest

from companion.link.command_service import CommandArgs, CommandService
from companion.link.commands import CameraCommands
from companion.link.microservice import Peer
from companion.messages import CommandId
from mavlink_dialect import companion as d
from tests.support.vehicle_port import RecordingVehicle, command_bench

GCS = Peer(255, 190, 0)


def bench(armed: bool) -> tuple[CommandService, RecordingVehicle]:
    return command_bench(CameraCommands, b"control.fixed_wing", armed)


def send(service: CommandService, command: int, *params: float) -> int | None:
    """The ack's result (None: deferred to the flight controller)."""
    full = (*params, *[0.0] * (7 - len(params)))
    out = service.dispatch(CommandArgs(command, full, 0, GCS), 0.0)
    return out[0].msg.result if out else None


def test_the_photo_button_goes_to_the_flight_controller_while_armed():
    service, vehicle = bench(armed=True)
    nan = math.nan  # MAVSDK sends unused parameters as NaN
    assert send(service, d.MAV_CMD_DO_DIGICAM_CONTROL, 0, 0, 0, 0, 1, 0, 0) is None
    assert send(service, d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, 25, nan, 1) is None
    assert send(service, d.MAV_CMD_IMAGE_START_CAPTURE, 0, 2, 0) is None
    assert send(service, d.MAV_CMD_IMAGE_STOP_CAPTURE) is None
    camera = CommandId.CAMERA
    assert vehicle.published == [
        (camera, (d.MAV_CMD_DO_DIGICAM_CONTROL, 0.0, 0.0, 0.0, 1.0)),
        (camera, (d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, 25.0, 0.0, 1.0, 0.0)),
        (camera, (d.MAV_CMD_IMAGE_START_CAPTURE, 0.0, 2.0, 0.0, 0.0)),
        (camera, (d.MAV_CMD_IMAGE_STOP_CAPTURE, 0.0, 0.0, 0.0, 0.0)),
    ]
    assert vehicle.texts == []


def test_disarmed_the_photo_button_is_refused_with_the_reason():
    service, vehicle = bench(armed=False)
    assert send(service, d.MAV_CMD_DO_DIGICAM_CONTROL, 0, 0, 0, 0, 1) == d.MAV_RESULT_DENIED
    assert vehicle.texts == ["Camera: photos only while armed"] and vehicle.published == []


@pytest.mark.parametrize(
    ("command", "params", "text"),
    [
        (d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, (-5.0,), "param1 (distance) -5 outside"),
        (d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, (math.nan,), "param1 (distance) is NaN"),
        (d.MAV_CMD_DO_SET_CAM_TRIGG_DIST, (math.inf,), "param1 (distance) is infinite"),
        (d.MAV_CMD_IMAGE_START_CAPTURE, (0.0, 1.0, 2.5), "param3 (total images) 2.5 is not"),
        (d.MAV_CMD_IMAGE_START_CAPTURE, (0.0, -1.0, 1.0), "param2 (interval) -1 outside"),
        (d.MAV_CMD_DO_DIGICAM_CONTROL, (0.0, 0.0, 0.0, 0.0, 7.0), "param5 (shoot) 7 outside"),
    ],
)
def test_hostile_parameters_are_refused_by_the_rules(command, params, text):
    service, vehicle = bench(armed=True)
    assert send(service, command, *params) == d.MAV_RESULT_DENIED
    assert vehicle.published == [] and text in vehicle.texts[0]
