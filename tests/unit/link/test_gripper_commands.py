"""DO_GRIPPER at the link, as MAVSDK's Gripper plug-in sends it (param1 the instance,
param2 0 release or 1 grab): handed to the flight controller while it runs (its ack
answers), refused with the reason while disarmed; broken parameters refused by the rules."""

from __future__ import annotations

import math

import pytest

from companion.link.command_service import CommandArgs, CommandService
from companion.link.commands import ServoCommands
from companion.link.microservice import Peer
from companion.messages import CommandId
from mavlink_dialect import companion as d
from tests.support.vehicle_port import RecordingVehicle, command_bench

GCS = Peer(255, 190, 0)


def bench(armed: bool) -> tuple[CommandService, RecordingVehicle]:
    return command_bench(ServoCommands, b"control.fixed_wing", armed)


def send(service: CommandService, *params: float) -> int | None:
    """The ack's result (None: deferred to the flight controller)."""
    full = (*params, *[math.nan] * (7 - len(params)))  # MAVSDK sends the rest as NaN
    out = service.dispatch(CommandArgs(d.MAV_CMD_DO_GRIPPER, full, 0, GCS), 0.0)
    return out[0].msg.result if out else None


def test_grab_and_release_go_to_the_flight_controller_while_armed():
    service, vehicle = bench(armed=True)
    assert send(service, 1, 1) is None
    assert send(service, 1, 0) is None
    assert vehicle.published == [(CommandId.GRIPPER, (1,)), (CommandId.GRIPPER, (0,))]
    assert vehicle.published_to == [b"control.fixed_wing"] * 2  # held until it listens
    assert vehicle.texts == []


def test_disarmed_it_is_refused_with_the_reason():
    service, vehicle = bench(armed=False)
    assert send(service, 1, 0) == d.MAV_RESULT_DENIED
    assert vehicle.texts == ["Gripper: works only while armed"] and vehicle.published == []


@pytest.mark.parametrize(
    ("params", "text"),
    [
        ((1.0, 2.0), "param2 (action) 2 outside"),
        ((1.0, 0.5), "param2 (action) 0.5 is not"),
        ((1.0, math.nan), "param2 (action) is NaN"),
        ((math.inf, 1.0), "param1 (instance) is infinite"),
    ],
)
def test_hostile_parameters_are_refused_by_the_rules(params, text):
    service, vehicle = bench(armed=True)
    assert send(service, *params) == d.MAV_RESULT_DENIED
    assert vehicle.published == [] and text in vehicle.texts[0]
