"""The parameter protocol against a running vehicle, as QGroundControl and MAVProxy use it."""

from __future__ import annotations

import time

import pytest
from pymavlink.dialects.v20 import common as m

from tests.protocol.mav_client import GroundStation, free_udp_port, two_stations
from tests.support.configs import link_vehicle


@pytest.fixture
def vehicle_and_gcs(vehicle_factory, tmp_path):
    def start():
        port = free_udp_port()
        vehicle = vehicle_factory(link_vehicle(f"udpin://127.0.0.1:{port}", tmp_path))
        gcs = GroundStation(port)
        gcs.connect()
        return vehicle, gcs

    return start


def fetch_all(gcs: GroundStation, ask: bool = True) -> dict[str, tuple[float, int, int]]:
    if ask:
        gcs.mav.param_request_list_send(1, 0)  # component 0: all, as QGroundControl asks
    got: dict[str, tuple[float, int, int]] = {}
    # Until every index or a deadline a busy machine does not reach: a pause mid-list is
    # not its end (a list that stops short fails the caller's count, as late as that).
    deadline = time.monotonic() + 15
    while time.monotonic() < deadline:
        msg = gcs.conn.recv_match(type="PARAM_VALUE", blocking=True, timeout=0.3)
        if msg is None:
            continue
        got[msg.param_id] = (msg.param_value, msg.param_index, msg.param_count)
        if len(got) == msg.param_count:
            break
    return got


def test_list_has_a_fixed_count_and_every_index_once(vehicle_and_gcs):
    _, gcs = vehicle_and_gcs()
    params = fetch_all(gcs)
    count = next(iter(params.values()))[2]
    assert len(params) == count >= 3
    assert sorted(p[1] for p in params.values()) == list(range(count))
    assert params["SR_ATTITUDE"][0] == 10.0


def test_read_by_name_and_by_index(vehicle_and_gcs):
    _, gcs = vehicle_and_gcs()
    gcs.mav.param_request_read_send(1, 1, b"SR_GPS", -1)
    by_name = gcs.recv("PARAM_VALUE", param_id="SR_GPS")
    gcs.mav.param_request_read_send(1, 1, b"", by_name.param_index)
    by_index = gcs.recv("PARAM_VALUE", param_index=by_name.param_index)
    assert by_index.param_id == "SR_GPS" and by_index.param_type == m.MAV_PARAM_TYPE_REAL32


def test_set_echoes_and_changes_the_stream_rate_and_survives_a_restart(vehicle_and_gcs):
    vehicle, gcs = vehicle_and_gcs()
    gcs.mav.param_set_send(1, 1, b"SR_ATTITUDE", 2.0, m.MAV_PARAM_TYPE_REAL32)
    assert gcs.recv("PARAM_VALUE", param_id="SR_ATTITUDE").param_value == 2.0
    gcs.conn.recv_match(type="NONE", blocking=True, timeout=0.5)
    count, t0 = 0, time.monotonic()
    while time.monotonic() - t0 < 2.0:
        if gcs.conn.recv_match(type="ATTITUDE", blocking=True, timeout=0.1):
            count += 1
    assert 2 <= count <= 6, f"{count} ATTITUDE in 2 s at SR_ATTITUDE = 2 Hz"
    gcs.close()
    vehicle.close()
    _, again = vehicle_and_gcs()  # same state_dir: the value was stored
    assert fetch_all(again)["SR_ATTITUDE"][0] == 2.0


def test_out_of_range_set_is_refused_with_the_old_value_echoed_and_a_statustext(vehicle_and_gcs):
    _, gcs = vehicle_and_gcs()
    gcs.mav.param_set_send(1, 1, b"SR_GPS", 500.0, m.MAV_PARAM_TYPE_REAL32)
    seen = {}
    deadline = time.monotonic() + 5
    while len(seen) < 2 and time.monotonic() < deadline:
        msg = gcs.conn.recv_match(type=["PARAM_VALUE", "STATUSTEXT"], blocking=True, timeout=0.2)
        if msg is not None and getattr(msg, "param_id", "SR_GPS") == "SR_GPS":
            seen[msg.get_type()] = msg
    assert seen["PARAM_VALUE"].param_value == 2.0
    assert "SR_GPS" in seen["STATUSTEXT"].text and "outside" in seen["STATUSTEXT"].text


def test_a_switch_set_half_on_is_refused_with_the_old_value_echoed(vehicle_and_gcs):
    """A 0/1 parameter is one of its two choices, never 0.5 (which one reader took as on
    and another as off). The reason is longer than one STATUSTEXT: its chunks join."""
    _, gcs = vehicle_and_gcs()
    gcs.mav.param_set_send(1, 1, b"SYS_FAILURE_EN", 0.5, m.MAV_PARAM_TYPE_REAL32)
    echoed, parts, text_id, whole = None, {}, None, False
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and not (echoed and whole):
        msg = gcs.conn.recv_match(type=["PARAM_VALUE", "STATUSTEXT"], blocking=True, timeout=0.2)
        if msg is None:
            continue
        if msg.get_type() == "PARAM_VALUE":
            echoed = msg if msg.param_id == "SYS_FAILURE_EN" else echoed
            continue
        if text_id is None and "SYS_FAILURE_EN" in msg.text:
            text_id = msg.id
        if text_id is not None and msg.id == text_id:
            parts[msg.chunk_seq] = msg.text
            whole = len(msg.text) < 50  # the last chunk holds the NUL
    assert echoed is not None and echoed.param_value == 0.0
    text = "".join(parts[k] for k in sorted(parts))
    assert text == "Param refused: SYS_FAILURE_EN: 0.5 is not one of 0, 1", text


def test_two_stations_asking_together_each_get_every_index(vehicle_factory, tmp_path):
    """QGroundControl on one endpoint and MAVProxy on another, connecting at once."""
    qgc, mavproxy = two_stations(vehicle_factory, tmp_path, "twostations")
    qgc.mav.param_request_list_send(1, 0)
    mavproxy.mav.param_request_list_send(1, 0)  # while the first list is going out
    for gcs in (qgc, mavproxy):
        params = fetch_all(gcs, ask=False)
        count = next(iter(params.values()))[2]
        assert count > 25  # longer than one burst: the second request comes mid-list
        assert sorted(p[1] for p in params.values()) == list(range(count))
