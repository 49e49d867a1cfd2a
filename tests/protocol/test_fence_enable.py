"""A geofence as MAVProxy meets it: SYS_STATUS's geofence bits (present, enabled, healthy
inside it) and DO_FENCE_ENABLE (its ``fence disable``) as a write of FENCE_ENABLE."""

from __future__ import annotations

from pymavlink.dialects.v20 import common as m

from tests.protocol.mav_client import GroundStation, answer
from tests.support.plugins import FakeNav
from tests.support.vehicle import wait_for

BIT = m.MAV_SYS_STATUS_GEOFENCE
FENCE = m.MAV_MISSION_TYPE_FENCE


def _upload_circle(gcs: GroundStation, radius_m: float) -> None:
    gcs.mav.mission_count_send(1, 1, 1, FENCE)
    assert gcs.recv("MISSION_REQUEST_INT", 10).seq == 0
    gcs.mav.mission_item_int_send(
        1, 1, 0, m.MAV_FRAME_GLOBAL, m.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION, 0, 1, radius_m, 0, 0,
        0, round(FakeNav.LAT * 1e7), round(FakeNav.LON * 1e7), 0, FENCE,
    )  # fmt: skip
    assert gcs.recv("MISSION_ACK", 10).type == m.MAV_MISSION_ACCEPTED


def _geofence_bits(gcs: GroundStation) -> tuple[int, int, int]:
    s = gcs.recv("SYS_STATUS")
    present, enabled = s.onboard_control_sensors_present, s.onboard_control_sensors_enabled
    return present & BIT, enabled & BIT, s.onboard_control_sensors_health & BIT


def test_the_bits_follow_the_fence_and_fence_enable_turns_it_off_and_on(client_gcs):
    assert _geofence_bits(client_gcs) == (0, 0, BIT)  # no fence: no "fence breach" at connect
    _upload_circle(client_gcs, 1000.0)
    inside = (BIT, BIT, BIT)  # FENCE_ENABLE's default is 1
    wait_for(lambda: _geofence_bits(client_gcs) == inside, 10, "the fence present, enabled, ok")
    ack, _ = answer(client_gcs, m.MAV_CMD_DO_FENCE_ENABLE, 0, target=(1, 0))
    assert ack.result == m.MAV_RESULT_ACCEPTED
    value = client_gcs.recv("PARAM_VALUE", param_id="FENCE_ENABLE")
    assert value.param_value == 0.0
    wait_for(lambda: _geofence_bits(client_gcs) == (BIT, 0, BIT), 10, "the fence disabled")
    client_gcs.mav.param_request_read_send(1, 1, b"FENCE_ENABLE", -1)
    assert client_gcs.recv("PARAM_VALUE", param_id="FENCE_ENABLE").param_value == 0.0
    ack, said = answer(client_gcs, m.MAV_CMD_DO_FENCE_ENABLE, 2)  # the floor only: none here
    assert ack.result == m.MAV_RESULT_DENIED and "no floor" in said
    ack, _ = answer(client_gcs, m.MAV_CMD_DO_FENCE_ENABLE, 1)
    assert ack.result == m.MAV_RESULT_ACCEPTED
    wait_for(lambda: _geofence_bits(client_gcs) == inside, 10, "the fence enabled again")


def test_a_fence_the_aircraft_is_outside_of_is_unhealthy(client_gcs):
    _upload_circle(client_gcs, 1000.0)
    wait_for(lambda: _geofence_bits(client_gcs) == (BIT, BIT, BIT), 10, "inside the fence")
    client_gcs.mav.mission_count_send(1, 1, 1, FENCE)  # a circle 1 km north: outside it
    assert client_gcs.recv("MISSION_REQUEST_INT", 10).seq == 0
    client_gcs.mav.mission_item_int_send(
        1, 1, 0, m.MAV_FRAME_GLOBAL, m.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION, 0, 1, 200.0, 0, 0,
        0, round((FakeNav.LAT + 0.01) * 1e7), round(FakeNav.LON * 1e7), 0, FENCE,
    )  # fmt: skip
    assert client_gcs.recv("MISSION_ACK", 10).type == m.MAV_MISSION_ACCEPTED
    wait_for(lambda: _geofence_bits(client_gcs) == (BIT, BIT, 0), 10, "the breach in SYS_STATUS")
