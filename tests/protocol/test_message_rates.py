"""Rate requests as QGroundControl's PID Tuning pages and MAVSDK's highres_imu example send
them: every message the vehicle streams is accepted at the rate it can serve (said back
in MESSAGE_INTERVAL), UNSUPPORTED only for one it cannot send at all."""

from __future__ import annotations

import asyncio
import itertools

import pytest
from mavsdk.asyncio import Configuration, Mavsdk
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.component_type import ComponentType

from companion.link.stream_schedule import MAX_RATE_HZ
from mavlink_dialect import companion as m
from tests.protocol.mav_client import GroundStation, connected_station, free_udp_port
from tests.support.configs import TICKER, client_vehicle, plugin

INTERVAL = m.MAV_CMD_SET_MESSAGE_INTERVAL
HUNDRED_HZ = 10_000
# src/Vehicle/MAVLinkStreamConfig.cc (4.4.5 and 5): the plane's Rate and Attitude pages,
# then its TECS page; each request sent once the previous one is acknowledged.
RATE_AND_ATTITUDE = (m.MAVLINK_MSG_ID_ATTITUDE_TARGET, m.MAVLINK_MSG_ID_ATTITUDE_QUATERNION)
TECS = (m.MAVLINK_MSG_ID_VFR_HUD, m.MAVLINK_MSG_ID_NAV_CONTROLLER_OUTPUT)


@pytest.fixture
def gcs(vehicle_factory, tmp_path):
    imu = plugin("imu", TICKER, rate_hz=100.0)
    yield from connected_station(vehicle_factory, lambda url: client_vehicle(url, tmp_path, (imu,)))


def _set(gcs: GroundStation, msg_id: int, interval_us: float) -> int:
    gcs.command(INTERVAL, msg_id, interval_us)
    return gcs.ack(INTERVAL).result


def test_qgroundcontrol_pid_tuning_pages_get_every_rate_they_ask_for(gcs):
    station = gcs
    for page in (RATE_AND_ATTITUDE, TECS):
        for msg_id in page:  # entering the page: 100 Hz
            assert _set(station, msg_id, HUNDRED_HZ) == m.MAV_RESULT_ACCEPTED, msg_id
            said = station.recv("MESSAGE_INTERVAL", 3.0, message_id=msg_id)
            assert said.interval_us == HUNDRED_HZ
        for msg_id in reversed(page):  # leaving it: the default rate
            assert _set(station, msg_id, 0) == m.MAV_RESULT_ACCEPTED, msg_id
    # Back at the default the attitude still comes: QGroundControl 4.4.5 reads the attitude
    # and heading from ATTITUDE_QUATERNION alone once it has seen one, and froze them when
    # the stream stopped after the page was left.
    station.conn.recv_match(type="NONE", blocking=True, timeout=0.3)  # the 100 Hz tail
    stamps = [station.recv("ATTITUDE_QUATERNION", 2.0).time_boot_ms for _ in range(12)]
    gaps = sorted(b - a for a, b in itertools.pairwise(stamps))
    assert 60 <= gaps[len(gaps) // 2] <= 150, gaps  # 10 Hz, as PX4 streams it
    # While on the page the attitude comes at 100 Hz by the vehicle's own clock.
    assert _set(station, m.MAVLINK_MSG_ID_ATTITUDE_QUATERNION, HUNDRED_HZ) == 0
    stamps = [station.recv("ATTITUDE_QUATERNION", 5.0).time_boot_ms for _ in range(60)]
    gaps = sorted(b - a for a, b in itertools.pairwise(stamps))
    assert gaps[len(gaps) // 2] <= 20, gaps  # the navigator's 50 Hz states, sent twice


def test_a_rate_beyond_the_vehicles_is_served_at_its_best_and_said(gcs):
    station = gcs
    imu = m.MAVLINK_MSG_ID_HIGHRES_IMU
    assert _set(station, imu, 5_000) == m.MAV_RESULT_ACCEPTED  # 200 Hz, as MAVSDK asks
    best = round(1e6 / MAX_RATE_HZ)
    assert station.recv("MESSAGE_INTERVAL", 3.0, message_id=imu).interval_us == best
    station.command(m.MAV_CMD_GET_MESSAGE_INTERVAL, imu)
    assert station.recv("MESSAGE_INTERVAL", 3.0, message_id=imu).interval_us == best
    sample = station.recv("HIGHRES_IMU", 5.0)
    assert sample.xacc > 0 and sample.fields_updated & m.HIGHRES_IMU_UPDATED_XACC
    # A message the vehicle cannot send at all: UNSUPPORTED, at once.
    assert _set(station, m.MAVLINK_MSG_ID_HIL_SENSOR, 5_000) == m.MAV_RESULT_UNSUPPORTED


async def _highres_imu_example(port: int) -> list:
    """MAVSDK-Python's examples/highres_imu.py, in the native binding: set_rate_imu(200),
    then the samples."""
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        system = await mavsdk.first_autopilot(timeout_s=15.0)
        assert system is not None
        telemetry = TelemetryAsync(system)
        await telemetry.set_rate_imu(200.0)  # raised TelemetryError UNSUPPORTED before
        samples = []
        async for imu in telemetry.subscribe_imu():
            samples.append(imu)
            if len(samples) == 20:
                return samples
    return []


@pytest.mark.timeout(120)
def test_mavsdk_highres_imu_example_gets_its_samples(vehicle_factory, tmp_path):
    port = free_udp_port()
    imu = plugin("imu", TICKER, rate_hz=100.0)
    vehicle = vehicle_factory(client_vehicle(f"udpout://127.0.0.1:{port}", tmp_path, (imu,)))
    vehicle.wait_running("link")
    samples = asyncio.run(asyncio.wait_for(_highres_imu_example(port), 60))
    assert len(samples) == 20
    assert all(s.acceleration_frd.forward_m_s2 > 0 for s in samples)
