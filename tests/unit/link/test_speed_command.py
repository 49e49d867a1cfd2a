"""DO_CHANGE_SPEED at the link, as MAVSDK's set_current_speed and pymavlink scripts send
it: checked against the airframe's AIRSPEED_MIN and AIRSPEED_MAX, then to the commander."""

from __future__ import annotations

import math

import pytest
from pymavlink.dialects.v20 import common as m

from companion.link.codec import new_encoder
from companion.link.command_rules import RULES, refusal
from companion.link.command_service import CommandArgs, CommandService
from companion.link.commands import SpeedCommands
from companion.link.microservice import Peer
from companion.link.params_service import ParamsService
from companion.messages import CommandId
from companion.params import ParamDecl, ParamStore
from tests.support.vehicle_port import RecordingVehicle

GCS = Peer(255, 190, 0)
LIMITS = (
    ParamDecl("AIRSPEED_MIN", 25.0, 5.0, 100.0, "m/s", "least"),
    ParamDecl("AIRSPEED_MAX", 45.0, 5.0, 120.0, "m/s", "most"),
)


def bench(decls=LIMITS) -> tuple[CommandService, RecordingVehicle]:
    mav = new_encoder(1, 1)
    service = CommandService(mav, 1, 1)
    service.guard(refusal, RULES)
    vehicle = RecordingVehicle()
    service.on_refusal = vehicle.statustext
    params = ParamsService(mav, ParamStore(decls), 1, 1)
    SpeedCommands(vehicle, params).register(service)
    return service, vehicle


def send(service: CommandService, *params: float) -> int | None:
    """The ack's result (None: deferred to the commander)."""
    full = (*params, *[0.0] * (7 - len(params)))
    out = service.dispatch(CommandArgs(m.MAV_CMD_DO_CHANGE_SPEED, full, 0, GCS), 0.0)
    return out[0].msg.result if out else None


def test_mavsdks_set_current_speed_goes_to_the_commander():
    service, vehicle = bench()
    assert send(service, 1, 30, -1, 0) is None  # ground speed 30, throttle unchanged
    assert vehicle.published == [(CommandId.CHANGE_SPEED, (30.0,))]
    assert send(service, 0, 40, 0) is None  # a pymavlink script's airspeed, throttle 0
    assert send(service, 0, -2, -1) is None  # back to the default
    assert vehicle.published[1] == (CommandId.CHANGE_SPEED, (40.0,))
    default = vehicle.published[2]
    assert default[0] == CommandId.CHANGE_SPEED and math.isnan(default[1][0])
    assert send(service, 0, -1, -1) == m.MAV_RESULT_ACCEPTED  # no change: nothing sent
    assert len(vehicle.published) == 3 and vehicle.texts == []


@pytest.mark.parametrize(
    ("params", "text"),
    [
        ((0, 60.0), "Change speed: 60 m/s outside AIRSPEED_MIN..MAX 25..45"),
        ((0, 10.0), "Change speed: 10 m/s outside AIRSPEED_MIN..MAX 25..45"),
        ((0, 0.0), "outside AIRSPEED_MIN..MAX"),
        ((0, math.nan), "DO_CHANGE_SPEED: param2 (speed) is NaN"),
        ((0, math.inf), "DO_CHANGE_SPEED: param2 (speed) is infinite"),
        ((0, 1e9), "param2 (speed) 1e+09 outside [-2, 1000]"),
        ((math.nan, 30.0), "param1 (speed type) is NaN"),
        ((7, 30.0), "param1 (speed type) 7 outside [0, 3]"),
        ((2, 3.0), "Change speed: climb and descent speeds not set"),
        ((0, 30.0, math.inf), "param3 (throttle) is infinite"),
    ],
)
def test_hostile_or_impossible_speeds_are_denied_counted_and_said(params, text):
    service, vehicle = bench()
    assert send(service, *params) == m.MAV_RESULT_DENIED
    assert vehicle.published == [] and service.refused == 1
    assert any(text in said for said in vehicle.texts), vehicle.texts


def test_without_a_flight_controller_or_a_commander_it_is_unsupported():
    service, vehicle = bench(decls=())
    assert send(service, 0, 30.0) == m.MAV_RESULT_UNSUPPORTED
    service, vehicle = bench()
    vehicle.commander = False
    assert send(service, 0, 30.0) == m.MAV_RESULT_UNSUPPORTED
    assert vehicle.published == []
