"""The older one-message requests, as MAVProxy and scripts still send them: the command's
own ack, then the message (as REQUEST_MESSAGE for it gives)."""

from __future__ import annotations

import math

from pymavlink.dialects.v20 import common as m

from tests.protocol.mav_client import GroundStation
from tests.support.plugins import FakeNav
from tests.support.vehicle import wait_for


def _home(gcs: GroundStation):
    gcs.command(m.MAV_CMD_GET_HOME_POSITION)
    if gcs.ack(m.MAV_CMD_GET_HOME_POSITION).result != m.MAV_RESULT_ACCEPTED:
        return None  # no home yet: TEMPORARILY_REJECTED
    return gcs.recv("HOME_POSITION")


def test_get_home_position_sends_home_with_the_vehicles_time(client_gcs):
    home = wait_for(lambda: _home(client_gcs), 10, "HOME_POSITION after GET_HOME_POSITION")
    assert (home.latitude, home.longitude) == (round(FakeNav.LAT * 1e7), round(FakeNav.LON * 1e7))
    assert home.time_usec > 0  # time since boot, as PX4 stamps it (it was 0)

    # The vehicle's time, not a constant: a later request is answered later (two answered
    # in the same millisecond of a busy machine's link step carry the same stamp).
    def later():
        again = _home(client_gcs)
        return again is not None and again.time_usec > home.time_usec

    wait_for(later, 10, "a later HOME_POSITION stamped later")


def test_request_protocol_version_is_acked_and_answered(client_gcs):
    client_gcs.command(m.MAV_CMD_REQUEST_PROTOCOL_VERSION, 1)  # param1 1, as the spec asks
    assert client_gcs.ack(m.MAV_CMD_REQUEST_PROTOCOL_VERSION).result == m.MAV_RESULT_ACCEPTED
    version = client_gcs.recv("PROTOCOL_VERSION")
    assert (version.version, version.min_version, version.max_version) == (200, 100, 200)


def test_hostile_parameters_of_the_requests_change_nothing(client_gcs):
    """Neither reads a parameter: NaN and infinity in them are ignored, answered once."""
    for command in (m.MAV_CMD_GET_HOME_POSITION, m.MAV_CMD_REQUEST_PROTOCOL_VERSION):
        client_gcs.command(command, math.nan, math.inf, -math.inf)
        ack = client_gcs.ack(command)
        assert ack.result in (m.MAV_RESULT_ACCEPTED, m.MAV_RESULT_TEMPORARILY_REJECTED)
