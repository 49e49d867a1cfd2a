"""Every command the link answers has its parameter rule: registering one without is refused."""

from __future__ import annotations

import pytest

from companion.control.mission.mission_files import MissionStore
from companion.link.codec import new_encoder
from companion.link.command_rules import RULES, refusal
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands import register_commands
from companion.link.endpoints import open_endpoint
from companion.link.identity import IdentityService
from companion.link.link_router import LinkRouter
from companion.link.microservice import Peer
from companion.link.mission_service import MissionService
from companion.link.params_service import ParamsService
from companion.params import ParamStore
from companion.sensors.imu_calibration import IMU_CAL_PARAMS
from mavlink_dialect import companion as d
from tests.support.vehicle_port import RecordingVehicle

GCS = Peer(255, 190, 0)


def linked_service() -> CommandService:
    """The link's command service with every group registered (as the plug-in does)."""
    mav = new_encoder(1, 1)
    identity = IdentityService(mav, 1, d.MAV_AUTOPILOT_PX4, 0)
    endpoint = open_endpoint("udpout://127.0.0.1:9")  # never written to here
    try:
        router = LinkRouter(mav, [endpoint], [], None)
        service = CommandService(mav, 1, 1)
        params = ParamsService(mav, ParamStore(IMU_CAL_PARAMS), 1, 1)
        missions = MissionService(mav, MissionStore(None), 1, 1)  # in memory
        register_commands(service, RecordingVehicle(), identity, router, None, params, missions)
    finally:
        endpoint.close()
    return service


def test_every_registered_command_has_a_rule_and_every_rule_a_command():
    service = linked_service()
    assert set(service.handlers) == set(RULES)
    assert d.MAV_CMD_DO_REPOSITION in service.handlers


def test_a_command_without_a_rule_cannot_be_registered():
    service = linked_service()
    with pytest.raises(KeyError, match=r"DO_SET_RELAY: no parameter rule .*command_rules\.py"):
        service.register(d.MAV_CMD_DO_SET_RELAY, lambda args: Outcome())
    ack = service.dispatch(CommandArgs(d.MAV_CMD_DO_SET_RELAY, (1.0,) * 7, 0, GCS), 0.0)
    assert ack[0].msg.result == d.MAV_RESULT_UNSUPPORTED  # as before: not answered blindly
    early = CommandService(new_encoder(1, 1), 1, 1)
    early.register(d.MAV_CMD_DO_SET_RELAY, lambda args: Outcome())
    with pytest.raises(KeyError, match="no parameter rule for DO_SET_RELAY"):
        early.guard(refusal, RULES)  # registered before the rules were put in front
