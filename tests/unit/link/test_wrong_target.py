"""Input addressed to another component of this system is not acted on, and is counted in
what ``companion status`` shows as refused; TIMESYNC honours its target as the rest do."""

from __future__ import annotations

from pathlib import Path

import pytest

from companion.control.mission.mission_files import MissionStore
from companion.flight_log import LogDirectory
from companion.link.codec import new_encoder
from companion.link.command_service import CommandService
from companion.link.link_router import _target_system
from companion.link.log_transfer import LogTransferService
from companion.link.metadata_service import MetadataService
from companion.link.microservice import Peer, refused_count
from companion.link.mission_service import MissionService
from companion.link.params_service import ParamsService
from companion.link.timesync import TimesyncService
from companion.params import ParamDecl, ParamStore

GCS = Peer(255, 190, 0)
OTHER_COMPONENT = 100  # a camera, say, on this system
DECLS = (ParamDecl("SR_ATTITUDE", 10.0, 0.0, 100.0, "Hz"),)


def _services(tmp_path: Path) -> dict[str, object]:
    mav = new_encoder(1, 1)
    return {
        "command": CommandService(mav, 1, 1),
        "params": ParamsService(mav, ParamStore(DECLS, None), 1, 1),
        "mission": MissionService(mav, MissionStore(None), 1, 1),
        "log": LogTransferService(mav, LogDirectory(tmp_path, 0), 1, 1, lambda i: 1e6),
        "ftp": MetadataService(mav, DECLS, 1, 1),
        "timesync": TimesyncService(mav, lambda: 42, 1, 1),
    }


def _message(kind: str, compid: int):
    gcs = new_encoder(255, 190)
    build = {
        "command": lambda: gcs.command_long_encode(1, compid, 400, 0, 1, 0, 0, 0, 0, 0, 0),
        "params": lambda: gcs.param_request_list_encode(1, compid),
        "mission": lambda: gcs.mission_request_list_encode(1, compid, 0),
        "log": lambda: gcs.log_request_list_encode(1, compid, 0, 0xFFFF),
        "ftp": lambda: gcs.file_transfer_protocol_encode(0, 1, compid, bytes(251)),
        "timesync": lambda: gcs.timesync_encode(0, 123, 1, compid),
    }
    return build[kind]()


@pytest.mark.parametrize("kind", ["command", "params", "mission", "log", "ftp", "timesync"])
def test_another_components_message_is_not_answered_and_is_counted(tmp_path, kind):
    services = _services(tmp_path)
    service = services[kind]
    assert service.handle(_message(kind, OTHER_COMPONENT), GCS, 0.0) == []
    assert service.rejected_target == 1
    assert refused_count(services.values()) == 1
    service.handle(_message(kind, 1), GCS, 0.0)
    assert service.rejected_target == 1  # its own component's is served, not counted


def test_timesync_answers_a_broadcast_and_its_own_component_addressed_to_the_requester():
    mav = new_encoder(1, 1)
    timesync = TimesyncService(mav, lambda: 42, 1, 1)
    gcs = new_encoder(255, 190)
    for request in (gcs.timesync_encode(0, 123), gcs.timesync_encode(0, 123, 1, 1)):
        (reply,) = timesync.handle(request, GCS, 0.0)
        assert (reply.msg.tc1, reply.msg.ts1) == (42, 123)
        assert (reply.msg.target_system, reply.msg.target_component) == (255, 190)
    assert timesync.handle(gcs.timesync_encode(0, 123, 1, 2), GCS, 0.0) == []
    assert timesync.rejected_target == 1
    assert timesync.handle(gcs.timesync_encode(7, 123, 1, 1), GCS, 0.0) == []  # a reply


def test_a_joystick_for_this_vehicle_is_not_forwarded_as_a_broadcast():
    gcs = new_encoder(255, 190)
    assert _target_system(gcs.manual_control_encode(1, 0, 0, 500, 0, 0)) == 1
    assert _target_system(gcs.manual_control_encode(0, 0, 0, 500, 0, 0)) == 0
    assert _target_system(gcs.heartbeat_encode(6, 8, 0, 0, 4)) == 0
    assert _target_system(gcs.param_request_list_encode(3, 1)) == 3
