"""DO_SET_MISSION_CURRENT (MAVProxy's ``wp set N``): what MISSION_SET_CURRENT does."""

from __future__ import annotations

import math

import pytest
from pymavlink.dialects.v20 import common as m

from tests.protocol.mav_client import GroundStation, answer, free_udp_port, upload_mission
from tests.support.configs import client_vehicle

MAVPROXY = (1, 0)  # MAVProxy addresses component 0 by default


@pytest.fixture
def station(vehicle_factory, tmp_path):
    port = free_udp_port()
    vehicle_factory(client_vehicle(f"udpin://127.0.0.1:{port}", tmp_path))
    gcs = GroundStation(port)
    gcs.connect()
    upload_mission(gcs)
    yield gcs
    gcs.close()


def test_the_item_becomes_current_in_mission_current_and_the_download(station):
    station.command(m.MAV_CMD_DO_SET_MISSION_CURRENT, 1, target=MAVPROXY)
    assert station.ack(m.MAV_CMD_DO_SET_MISSION_CURRENT).result == m.MAV_RESULT_ACCEPTED
    current = station.recv("MISSION_CURRENT", seq=1)
    assert current.total == 2
    station.mav.mission_request_int_send(1, 1, 1, m.MAV_MISSION_TYPE_MISSION)
    assert station.recv("MISSION_ITEM_INT", seq=1).current == 1
    station.command(m.MAV_CMD_DO_SET_MISSION_CURRENT, -1, 1)  # -1: keep it (and reset)
    assert station.ack(m.MAV_CMD_DO_SET_MISSION_CURRENT).result == m.MAV_RESULT_ACCEPTED
    assert station.recv("MISSION_CURRENT").seq == 1


@pytest.mark.parametrize(
    ("item", "text"),
    [
        (2, "no item 2 (the mission has 2 items)"),
        (math.nan, "param1 (item) is NaN"),
        (math.inf, "param1 (item) is infinite"),
        (-2, "param1 (item) -2 outside [-1, 65535]"),
        (0.5, "is not a whole number"),
    ],
)
def test_an_item_the_mission_lacks_is_denied_with_the_reason(station, item, text):
    station.command(m.MAV_CMD_DO_SET_MISSION_CURRENT, 1)
    assert station.ack(m.MAV_CMD_DO_SET_MISSION_CURRENT).result == m.MAV_RESULT_ACCEPTED
    ack, said = answer(station, m.MAV_CMD_DO_SET_MISSION_CURRENT, item, target=MAVPROXY)
    assert ack.result == m.MAV_RESULT_DENIED
    assert text in said
    assert station.recv("MISSION_CURRENT").seq == 1  # unchanged
