"""DO_SET_ACTUATOR at the link, as MAVSDK's ``Action.set_actuator(index, value)`` sends it
(the set's parameter its value, every other parameter NaN): handed to the flight controller
while it runs (its ack answers), refused with the reason while disarmed; values outside
-1..1, infinities and a fractional index refused by the rules before anything moves."""

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
NAN = math.nan


def bench(armed: bool) -> tuple[CommandService, RecordingVehicle]:
    return command_bench(ServoCommands, b"control.fixed_wing", armed)


def send(service: CommandService, params: tuple[float, ...]) -> int | None:
    """The ack's result (None: deferred to the flight controller)."""
    out = service.dispatch(CommandArgs(d.MAV_CMD_DO_SET_ACTUATOR, params, 0, GCS), 0.0)
    return out[0].msg.result if out else None


def mavsdk(index: int, value: float) -> tuple[float, ...]:
    """MAVSDK's encoding for a set of 1-6: its parameter the value, the rest NaN, and the
    index (param7) 0."""
    params = [NAN] * 6
    params[index - 1] = value
    return (*params, 0.0)


def test_a_set_goes_to_the_flight_controller_while_armed_nan_meaning_leave():
    service, vehicle = bench(armed=True)
    assert send(service, mavsdk(1, 0.5)) is None
    assert send(service, (NAN,) * 7) is None  # no index given: set 1-6
    (cmd, params), (_, all_left) = vehicle.published
    assert cmd == CommandId.SET_ACTUATOR and params[0] == 0.5 and params[6] == 0.0
    assert all(math.isnan(p) for p in params[1:6]) and all(math.isnan(p) for p in all_left[:6])
    assert all_left[6] == 0.0
    assert vehicle.published_to == [b"control.fixed_wing"] * 2


def test_disarmed_it_is_refused_with_the_reason():
    service, vehicle = bench(armed=False)
    assert send(service, mavsdk(2, -1.0)) == d.MAV_RESULT_DENIED
    assert vehicle.texts == ["Set actuator: works only while armed"]
    assert vehicle.published == []


@pytest.mark.parametrize(
    ("params", "text"),
    [
        (mavsdk(1, 1.5), "param1 (actuator 1) 1.5 outside [-1, 1]"),
        (mavsdk(6, -math.inf), "param6 (actuator 6) is infinite"),
        ((*mavsdk(3, 0.2)[:6], 0.5), "param7 (index) 0.5 is not a whole number"),
    ],
)
def test_hostile_parameters_are_refused_by_the_rules(params, text):
    service, vehicle = bench(armed=True)
    assert send(service, params) == d.MAV_RESULT_DENIED
    assert vehicle.published == [] and text in vehicle.texts[0]
