"""Link budget (acks first, telemetry decimated), .tlog recording and TIMESYNC."""

from __future__ import annotations

import time

from pymavlink import mavutil
from pymavlink.dialects.v20 import common as m

from companion.link.link_budget import LinkBudget
from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.support.configs import link_vehicle
from tests.support.vehicle import wait_for


def start(vehicle_factory, query: str, tmp_path) -> GroundStation:
    port = free_udp_port()
    vehicle_factory(link_vehicle(f"udpin://127.0.0.1:{port}{query}", tmp_path))
    gcs = GroundStation(port)
    gcs.connect()
    return gcs


def test_budget_bucket_lets_priority_overdraw_and_skips_telemetry():
    budget = LinkBudget(rate_bytes_s=1000.0)
    assert budget.take_telemetry(40, 0.0)
    budget.take_priority(400, 0.0)  # the bucket (300 B minimum) is now overdrawn
    assert not budget.take_telemetry(40, 0.01)
    assert budget.take_telemetry(40, 0.5)  # refilled at 1000 B/s
    assert budget.skipped == 1
    budget.radio_status(txbuf_pct=10)
    assert budget.scale < 1.0


def test_a_slow_link_decimates_telemetry_but_answers_commands_first(vehicle_factory, tmp_path):
    gcs = start(vehicle_factory, "?budget=1500", tmp_path)  # ~1.5 kB/s: about a 14400-baud radio
    gcs.command(m.MAV_CMD_SET_MESSAGE_INTERVAL, m.MAVLINK_MSG_ID_ATTITUDE, 10000)  # 100 Hz asked
    gcs.ack(m.MAV_CMD_SET_MESSAGE_INTERVAL)
    counts = {"ATTITUDE": 0, "bytes": 0}

    def count(_conn, msg) -> None:
        if msg.get_srcSystem() == 1:
            counts["bytes"] += len(msg.get_msgbuf())
        if msg.get_type() == "ATTITUDE":
            counts["ATTITUDE"] += 1

    gcs.conn.message_hooks.append(count)
    t0 = time.monotonic()
    latencies = []
    while time.monotonic() - t0 < 3.0:
        sent = time.monotonic()
        gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AUTOPILOT_VERSION)
        gcs.ack(m.MAV_CMD_REQUEST_MESSAGE, timeout_s=2.0)
        latencies.append(time.monotonic() - sent)
        gcs.conn.recv_match(type="NONE", blocking=True, timeout=0.2)  # a command every 0.2 s
    received = counts["ATTITUDE"]
    bytes_per_s = counts["bytes"] / (time.monotonic() - t0)
    # Everything the vehicle sent fits the budget (plus the bucket's one burst).
    assert bytes_per_s < 1500 + 300 / 3.0, f"the link carried {bytes_per_s:.0f} B/s"
    assert received > 10, "telemetry still flows within the budget"
    assert max(latencies) < 0.5


def test_tlog_records_both_directions_readable_by_pymavlink(vehicle_factory, tmp_path):
    tlog = tmp_path / "link.tlog"
    gcs = start(vehicle_factory, f"?tlog={tlog}", tmp_path)
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AUTOPILOT_VERSION)
    gcs.ack(m.MAV_CMD_REQUEST_MESSAGE)

    # Read until the log holds the exchange and half a second of telemetry: on a busy
    # machine the link process may take longer than that to write it.
    def recorded() -> dict[tuple[str, int], int]:
        log = mavutil.mavlink_connection(str(tlog))
        types: dict[tuple[str, int], int] = {}
        while (msg := log.recv_msg()) is not None:
            key = (msg.get_type(), msg.get_srcSystem())
            types[key] = types.get(key, 0) + 1
        log.close()
        return types

    def complete(t: dict[tuple[str, int], int]) -> bool:
        return t.get(("ATTITUDE", 1), 0) >= 5 and ("COMMAND_ACK", 1) in t

    types = wait_for(lambda: t if complete(t := recorded()) else None, 60, "the exchange")
    assert types.get(("HEARTBEAT", 1), 0) >= 1, "the vehicle's own heartbeats"
    assert types.get(("HEARTBEAT", 255), 0) >= 1, "the ground station's heartbeats"
    assert types.get(("COMMAND_LONG", 255)) == 1 and types.get(("COMMAND_ACK", 1)) == 1
    assert types.get(("ATTITUDE", 1), 0) >= 5


def test_timesync_request_is_answered_with_the_request_echoed(vehicle_factory, tmp_path):
    gcs = start(vehicle_factory, "", tmp_path)
    gcs.mav.timesync_send(0, 123456789)
    reply = gcs.recv("TIMESYNC", 3, ts1=123456789)
    assert reply.tc1 > 0
