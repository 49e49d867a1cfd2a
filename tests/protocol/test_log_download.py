"""The vehicle's flight logs, listed, downloaded and erased over MAVLink as QGroundControl's
Log Download page and MAVProxy's ``log`` module do it, from a vehicle that recorded a flight."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from pyulog import ULog

from companion.flight_log import being_written
from companion.messages import CommandId, VehicleCommand
from mavlink_dialect import companion as m
from tests.protocol.log_client import QgcDownload, list_logs, mavproxy_download
from tests.protocol.lossy_hop import LossyHop
from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.protocol.test_mavproxy import MavProxy
from tests.support.configs import (
    FAKE_NAV,
    TICKER,
    WAITING,
    link,
    link_vehicle,
    plugin,
    vehicle_config,
)
from tests.support.vehicle import Vehicle, wait_for

MIN_LOG_BYTES = 120_000  # more than two of QGroundControl's 46080-byte chunks


def logging_vehicle(vehicle_factory, port: int, state: Path) -> Vehicle:
    return vehicle_factory(
        vehicle_config(
            "logged",
            link(f"udpin://127.0.0.1:{port}"),
            plugin("logger", "system.logger", flush_s=0.2),
            plugin("nav", FAKE_NAV),
            plugin("imu", TICKER, rate_hz=400.0),
            plugin("flight", WAITING, group="flight"),
            state_dir=state,
        )
    )


def _command(vehicle: Vehicle, command: CommandId, seq: int) -> None:
    assert vehicle.bus is not None
    vehicle.bus.writer("link/commands").publish(
        VehicleCommand(t_us=0, seq=seq, command=int(command))
    )


def record_flight(vehicle: Vehicle, logs: Path) -> Path:
    """Arm, record until the log is a few chunks long, disarm; the closed log."""
    wait_for(lambda: (r := vehicle.row("logger")) is not None and r.step_p50_us > 0, 30, "logger")
    _command(vehicle, CommandId.START, 1)
    wait_for(lambda: any(p.stat().st_size > MIN_LOG_BYTES for p in logs.glob("*.ulg")), 60, "a log")
    _command(vehicle, CommandId.STOP, 2)
    (path,) = logs.glob("*.ulg")
    wait_for(lambda: not being_written(path), 30, "the log closed")
    return path


def refused(vehicle: Vehicle) -> int:
    return int(vehicle.row("link").refused)


@pytest.mark.timeout(240)
def test_qgc_lists_downloads_with_losses_and_erases(vehicle_factory, tmp_path):
    port = free_udp_port()
    state = tmp_path / "state"
    vehicle = logging_vehicle(vehicle_factory, port, state)
    on_board = record_flight(vehicle, state / "logs")
    gcs = GroundStation(port)
    try:
        gcs.connect()
        entries = list_logs(gcs)
        assert list(entries) == [0]
        assert entries[0].size == on_board.stat().st_size
        assert entries[0].num_logs == 1 and entries[0].last_log_num == 0
        assert abs(entries[0].time_utc - time.time()) < 3600  # a date QGC shows

        # Every 13th packet lost on the way, once: QGC's re-requests fill the holes.
        lost: set[int] = set()

        def drop(ofs: int) -> bool:
            if ofs // 90 % 13 == 5 and ofs not in lost:
                lost.add(ofs)
                return True
            return False

        download = QgcDownload(gcs, 0, entries[0].size, drop)
        data = download.run()
        assert download.dropped > 10 and download.requests > download.dropped // 20
        assert data == on_board.read_bytes()
        copy = tmp_path / "log_0.ulg"
        copy.write_bytes(data)
        ulog = ULog(str(copy))
        assert ulog.msg_info_dict["vehicle_name"] == "logged"
        # How many samples fill MIN_LOG_BYTES depends on how the machine scheduled the
        # ticker against the other channels (979 seen beside other jobs); hundreds of
        # ordered samples is what a readable log of a few seconds at 400 Hz holds.
        imu_t = ulog.get_dataset("sensors_imu").data["timestamp"]
        assert len(imu_t) > 400 and (imu_t[1:] > imu_t[:-1]).all()

        gcs.mav.log_erase_send(1, 1)
        wait_for(lambda: not on_board.exists(), 10, "the log erased")
        assert list_logs(gcs) == {}
    finally:
        gcs.close()


@pytest.mark.timeout(240)
def test_hostile_requests_are_refused_and_erase_waits_for_disarm(vehicle_factory, tmp_path):
    port = free_udp_port()
    state = tmp_path / "state"
    vehicle = logging_vehicle(vehicle_factory, port, state)
    on_board = record_flight(vehicle, state / "logs")
    size = on_board.stat().st_size
    gcs = GroundStation(port)
    try:
        gcs.connect()
        before = refused(vehicle)
        mav = gcs.mav
        mav.log_request_data_send(1, 1, 7, 0, 90)  # no such log
        mav.log_request_data_send(1, 1, 0xFFFF, 0, 0xFFFFFFFF)
        mav.log_request_data_send(1, 1, 0, size + 90, 90)  # past the end
        mav.log_request_data_send(1, 1, 0, 0xFFFFFFFF, 0xFFFFFFFF)
        mav.log_request_data_send(1, 1, 0, 0, 0)  # nothing asked
        mav.log_request_list_send(1, 1, 5, 2)  # an empty range
        mav.log_request_list_send(1, 1, 3, 0xFFFF)  # beyond the last log
        wait_for(lambda: refused(vehicle) >= before + 7, 10, "seven refusals counted")
        assert gcs.conn.recv_match(type="LOG_DATA", blocking=True, timeout=1.0) is None

        # The end of the log: the last bytes, then nothing past them.
        tail = size - size % 90 if size % 90 else size - 90
        mav.log_request_data_send(1, 1, 0, tail, 0xFFFFFFFF)
        last = gcs.recv("LOG_DATA", 10, ofs=tail)
        assert bytes(last.data[: last.count]) == on_board.read_bytes()[tail:]

        _command(vehicle, CommandId.START, 3)
        wait_for(lambda: len(list(on_board.parent.glob("*.ulg"))) == 2, 30, "a second log")
        armed = m.MAV_MODE_FLAG_SAFETY_ARMED
        wait_for(lambda: gcs.recv("HEARTBEAT", 5).base_mode & armed, 30, "armed, as QGC sees")
        mav.log_erase_send(1, 1)
        gcs.recv("STATUSTEXT", 10, text="Logs not erased: armed")  # told why
        assert on_board.exists()
        _command(vehicle, CommandId.STOP, 4)
        wait_for(lambda: not any(map(being_written, on_board.parent.glob("*.ulg"))), 30, "closed")
        mav.log_erase_send(1, 1)
        wait_for(lambda: not list(on_board.parent.glob("*.ulg")), 10, "every log erased")
    finally:
        gcs.close()


@pytest.mark.timeout(240)
def test_mavproxy_log_list_and_download(vehicle_factory, tmp_path):
    port = free_udp_port()
    state = tmp_path / "state"
    vehicle = logging_vehicle(vehicle_factory, port, state)
    on_board = record_flight(vehicle, state / "logs")
    mavproxy = MavProxy(port, tmp_path)
    size = on_board.stat().st_size
    data = mavproxy_download(mavproxy, tmp_path, lambda: mavproxy.connected(vehicle), size, 120)
    assert data == on_board.read_bytes()


@pytest.mark.timeout(240)
def test_mavproxy_downloads_a_log_of_whole_packets_whole_through_a_lost_packet(
    vehicle_factory, tmp_path
):
    """MAVProxy ends a download at a count-0 packet whatever it still lacks: a log whose
    size is a multiple of 90 bytes, one packet of it lost on the way, comes down whole
    (MAVProxy asks for the hole in the silence after the stream, then for the end)."""
    port = free_udp_port()
    state = tmp_path / "state"
    (state / "logs").mkdir(parents=True)
    on_board = state / "logs" / "0001_armed.ulg"
    on_board.write_bytes(bytes(range(256)) * 450)  # 115200 bytes: 1280 whole packets
    vehicle = vehicle_factory(link_vehicle(f"udpin://127.0.0.1:{port}", state))
    vehicle.wait_running("link")
    lost: set[int] = set()

    def drop(msg) -> bool:
        if msg.get_type() == "LOG_DATA" and msg.ofs == 23040 and msg.ofs not in lost:
            lost.add(msg.ofs)
            return True
        return False

    hop = LossyHop(port, drop)
    try:
        mavproxy = MavProxy(hop.port, tmp_path)
        size = on_board.stat().st_size
        data = mavproxy_download(mavproxy, tmp_path, lambda: mavproxy.connected(vehicle), size, 120)
    finally:
        hop.close()
    assert lost == {23040}
    assert data == on_board.read_bytes()
