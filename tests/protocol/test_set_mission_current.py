"""DO_SET_MISSION_CURRENT (MAVProxy's ``wp set N``) and the MISSION_SET_CURRENT message
(QGroundControl's "set current waypoint", MAVSDK's ``set_current_mission_item``): both go
to the commander, which makes the item the one a mission flies to (or starts at); on the
ground one beyond the mission's take-off is refused with the reason (it would skip it)."""

from __future__ import annotations

import math
import time

import pytest
from pymavlink.dialects.v20 import common as m

from tests.protocol.mav_client import GroundStation, answer, upload_mission

MAVPROXY = (1, 0)  # MAVProxy addresses component 0 by default


def _upload_waypoints(gcs: GroundStation, count: int) -> None:
    """A mission of ``count`` waypoints and no take-off (MAVSDK's mission plug-in's kind)."""
    mav = gcs.mav
    mav.mission_count_send(1, 1, count, m.MAV_MISSION_TYPE_MISSION)
    for _ in range(count):
        req = gcs.recv(["MISSION_REQUEST_INT", "MISSION_REQUEST"], 10)
        mav.mission_item_int_send(
            1, 1, req.seq, m.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, m.MAV_CMD_NAV_WAYPOINT, 0, 1,
            0, 0, 0, 0, round((-37.9105 + 0.002 * (req.seq + 1)) * 1e7), round(145.134 * 1e7),
            50, m.MAV_MISSION_TYPE_MISSION,
        )  # fmt: skip
    assert gcs.recv("MISSION_ACK", 10).type == m.MAV_MISSION_ACCEPTED


def _said(gcs: GroundStation, text: str, timeout_s: float = 10.0) -> None:
    """A STATUSTEXT saying ``text`` comes (a commander's reason follows its ack; a long one
    in chunks of 50 characters: its first is enough)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        msg = gcs.conn.recv_match(type="STATUSTEXT", blocking=True, timeout=0.2)
        if msg is not None and msg.text and text.startswith(msg.text):
            return
    raise AssertionError(f"{text!r} not said within {timeout_s} s")


@pytest.fixture
def station(client_gcs):
    _upload_waypoints(client_gcs, 3)
    return client_gcs


def test_the_item_becomes_current_in_mission_current_and_the_download(station):
    station.command(m.MAV_CMD_DO_SET_MISSION_CURRENT, 2, target=MAVPROXY)
    assert station.ack(m.MAV_CMD_DO_SET_MISSION_CURRENT).result == m.MAV_RESULT_ACCEPTED
    current = station.recv("MISSION_CURRENT", seq=2)
    assert current.total == 3
    station.mav.mission_request_int_send(1, 1, 2, m.MAV_MISSION_TYPE_MISSION)
    assert station.recv("MISSION_ITEM_INT", seq=2).current == 1
    station.command(m.MAV_CMD_DO_SET_MISSION_CURRENT, -1, 1)  # -1: keep it (and reset)
    assert station.ack(m.MAV_CMD_DO_SET_MISSION_CURRENT).result == m.MAV_RESULT_ACCEPTED
    assert station.recv("MISSION_CURRENT").seq == 2


def test_the_message_makes_the_item_current_too(station):
    station.mav.mission_set_current_send(1, 1, 1)
    assert station.recv("MISSION_CURRENT", seq=1).total == 3


def test_on_the_ground_an_item_beyond_the_take_off_is_refused_with_the_reason(client_gcs):
    upload_mission(client_gcs)  # take-off, then a waypoint
    station = client_gcs
    station.command(m.MAV_CMD_DO_SET_MISSION_CURRENT, 1, target=MAVPROXY)
    assert station.ack(m.MAV_CMD_DO_SET_MISSION_CURRENT).result == m.MAV_RESULT_DENIED
    _said(station, "Set mission item: 1 skips the take-off (item 0) on the ground")
    station.mav.mission_set_current_send(1, 1, 1)  # the message: the reason said alike
    _said(station, "Set mission item: 1 skips the take-off (item 0) on the ground")
    assert station.recv("MISSION_CURRENT").seq == 0  # unchanged
    station.command(m.MAV_CMD_DO_SET_MISSION_CURRENT, 0, target=MAVPROXY)
    assert station.ack(m.MAV_CMD_DO_SET_MISSION_CURRENT).result == m.MAV_RESULT_ACCEPTED


@pytest.mark.parametrize(
    ("item", "text"),
    [
        (3, "no item 3 (the mission has 3 items)"),
        (math.nan, "param1 (item) is NaN"),
        (math.inf, "param1 (item) is infinite"),
        (-2, "param1 (item) -2 outside [-1, 65535]"),
        (0.5, "is not a whole number"),
    ],
)
def test_an_item_the_mission_lacks_is_denied_with_the_reason(station, item, text):
    station.command(m.MAV_CMD_DO_SET_MISSION_CURRENT, 1)
    assert station.ack(m.MAV_CMD_DO_SET_MISSION_CURRENT).result == m.MAV_RESULT_ACCEPTED
    station.recv("MISSION_CURRENT", seq=1)
    ack, said = answer(station, m.MAV_CMD_DO_SET_MISSION_CURRENT, item, target=MAVPROXY)
    assert ack.result == m.MAV_RESULT_DENIED
    assert text in said
    assert station.recv("MISSION_CURRENT").seq == 1  # unchanged


def test_mission_start_param1_as_px4_nan_keeps_the_item_set_an_item_is_a_set_current(station):
    station.command(m.MAV_CMD_DO_SET_MISSION_CURRENT, 2, target=MAVPROXY)
    assert station.ack(m.MAV_CMD_DO_SET_MISSION_CURRENT).result == m.MAV_RESULT_ACCEPTED
    station.recv("MISSION_CURRENT", seq=2)
    for first in (math.nan, -1):
        station.command(m.MAV_CMD_MISSION_START, first, math.nan)
        assert station.ack(m.MAV_CMD_MISSION_START).result == m.MAV_RESULT_ACCEPTED
    time.sleep(0.5)
    while station.conn.recv_match(blocking=False) is not None:  # what came before
        pass
    assert station.recv("MISSION_CURRENT").seq == 2
    station.command(m.MAV_CMD_MISSION_START, 0, math.nan)
    assert station.ack(m.MAV_CMD_MISSION_START).result == m.MAV_RESULT_ACCEPTED
    station.recv("MISSION_CURRENT", seq=0)
