"""QGroundControl's connect sequence (../shared/MAVLINK.md), step by step, each answered."""

from __future__ import annotations

import time

from mavlink_dialect import companion as m
from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.support.configs import link_vehicle


def ask(gcs: GroundStation, msg_id: int, expect: int, timeout_s: float = 1.0):
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, msg_id)
    t0 = time.monotonic()
    ack = gcs.ack(m.MAV_CMD_REQUEST_MESSAGE, timeout_s)
    assert ack.result == expect, f"REQUEST_MESSAGE {msg_id}: result {ack.result}"
    assert time.monotonic() - t0 < timeout_s
    return ack


def test_qgroundcontrol_connect_sequence_gets_every_answer_at_once(vehicle_factory, tmp_path):
    port = free_udp_port()
    vehicle_factory(link_vehicle(f"udpin://127.0.0.1:{port}", tmp_path))
    gcs = GroundStation(port)  # sysid 255, compid 190, as QGroundControl
    gcs.connect()

    ask(gcs, m.MAVLINK_MSG_ID_AUTOPILOT_VERSION, m.MAV_RESULT_ACCEPTED)
    caps = gcs.recv("AUTOPILOT_VERSION").capabilities
    for bit in ("MISSION_INT", "COMMAND_INT", "MAVLINK2", "PARAM_ENCODE_C_CAST"):
        assert caps & getattr(m, f"MAV_PROTOCOL_CAPABILITY_{bit}"), bit
    assert caps & m.MAV_PROTOCOL_CAPABILITY_MISSION_FENCE
    assert caps & m.MAV_PROTOCOL_CAPABILITY_MISSION_RALLY
    assert caps & m.MAV_PROTOCOL_CAPABILITY_FTP  # read-only: the metadata files

    ask(gcs, m.MAVLINK_MSG_ID_PROTOCOL_VERSION, m.MAV_RESULT_ACCEPTED)
    version = gcs.recv("PROTOCOL_VERSION")
    assert (version.version, version.min_version, version.max_version) == (200, 100, 200)

    ask(gcs, 397, m.MAV_RESULT_ACCEPTED)  # COMPONENT_METADATA (test_component_metadata)
    assert gcs.recv("COMPONENT_METADATA").uri.startswith("mftp://")
    for unsupported in (259, 280):  # camera, gimbal
        ask(gcs, unsupported, m.MAV_RESULT_UNSUPPORTED)
    gcs.command(521)  # MAV_CMD_REQUEST_CAMERA_INFORMATION
    assert gcs.ack(521, 1.0).result == m.MAV_RESULT_UNSUPPORTED

    gcs.mav.param_request_list_send(1, 0)
    first = gcs.recv("PARAM_VALUE", 1.5)
    assert first.param_count >= 1 and first.get_srcComponent() == 1

    for _ in range(2):
        gcs.mav.system_time_send(int(time.time() * 1e6), 0)

    for mission_type in (0, 1, 2):
        gcs.mav.mission_request_list_send(1, 1, mission_type)
        count = gcs.recv("MISSION_COUNT", 1.5, mission_type=mission_type)
        assert count.count == 0
    gcs.close()
