"""A mission flown in ``companion sim`` leaves an on-board ULog that QGroundControl's way of
downloading (pymavlink) and MAVProxy's ``log download`` both fetch byte for byte while the
vehicle is still up, that pyulog reads, and that holds every IMU sample the driver
published, as its own counters (``system/plugin_stats``) say."""

from __future__ import annotations

import itertools
import logging
import math
import re
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from pyulog import ULog

from companion.bus.node import BusNode
from companion.flight_log import being_written
from mavlink_dialect import companion as m
from tests.protocol.log_client import QgcDownload, list_logs, mavproxy_download
from tests.protocol.mav_client import GroundStation
from tests.protocol.test_mavproxy import MavProxy
from tests.support.vehicle import REPO, wait_for

log = logging.getLogger(__name__)
PLAN = str(REPO / "qgc_plans" / "short_leg.plan")
START_AT_S = 5.0
FORCE_DISARM = 21196
# Every channel of the shipped logger that this flight produces: each sensor the simulated
# aircraft carries, the navigator, the controller, the servos, the commander and the link.
TOPICS = {
    "sensors_imu", "sensors_mag", "sensors_gps", "sensors_compass", "sensors_baro",
    "sensors_battery", "nav_state", "control_actuators", "control_status",
    "actuators_servos", "vehicle_status", "link_commands", "link_command_acks",
    "system_health",
}  # fmt: skip


class Flight:
    """The test's view of the flying vehicle: MAVLink as QGC, and the IMU driver's counters."""

    def __init__(self, namespace: str, port: int) -> None:
        self.gcs = GroundStation(port)
        self.bus = BusNode(namespace, "test")
        self.stats = self.bus.queue_reader("system/plugin_stats")
        self.imu_counts: list[tuple[int, int]] = []  # (t_us, samples published by then)

    def poll(self, kind: str | list[str]) -> Any:
        self.gcs.heartbeat()
        for msg in self.stats.drain():
            if msg.name.decode() == "imu":
                self.imu_counts.append((int(msg.t_us), int(msg.frames_ok)))
        return self.gcs.conn.recv_match(type=kind, blocking=True, timeout=0.2)

    def close(self) -> None:
        self.gcs.close()
        self.bus.close()


def fly_the_leg(flight: Flight, timeout_s: float) -> int:
    """Wait until the mission flies its second waypoint (take-off and the first leg
    done); the vehicle's time then, in ms."""
    deadline = time.monotonic() + timeout_s
    seq, now_ms = -1, 0
    while seq < 2:
        assert time.monotonic() < deadline, f"mission item {seq} at {now_ms} ms"
        msg = flight.poll(["MISSION_CURRENT", "GLOBAL_POSITION_INT"])
        if msg is not None and msg.get_type() == "MISSION_CURRENT":
            seq = msg.seq
        elif msg is not None:
            now_ms = msg.time_boot_ms
    return now_ms


def disarm(flight: Flight, timeout_s: float = 60.0) -> None:
    """A forced disarm in flight closes the flight's log (the simulation flies on)."""
    cmd = m.MAV_CMD_COMPONENT_ARM_DISARM
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        flight.gcs.command(cmd, 0, FORCE_DISARM)
        ack = flight.poll("COMMAND_ACK")
        if ack is not None and ack.command == cmd:
            assert ack.result == m.MAV_RESULT_ACCEPTED, ack
            return
    raise AssertionError("no acknowledgement of the disarm")


def download_with_mavproxy(master: str, folder: Path, size: int) -> bytes:
    mavproxy = MavProxy(master, folder)

    def online() -> None:
        # Typed once MAVProxy has heard the vehicle (the link's counters include QGC's
        # frames here, so MavProxy.connected would not tell).
        wait_for(lambda: "online system 1" in "".join(mavproxy.lines), 60, "MAVProxy online")
        time.sleep(2.0)

    return mavproxy_download(mavproxy, folder, online, size, 300)


def download_both(flight: Flight, master: str, folder: Path, size: int) -> tuple[bytes, bytes]:
    """The log as QGroundControl downloads it, then as MAVProxy does."""
    started = time.monotonic()
    by_qgc = QgcDownload(flight.gcs, 0, size).run()
    qgc_s, started = time.monotonic() - started, time.monotonic()
    by_mavproxy = download_with_mavproxy(master, folder, size)
    took = (qgc_s, time.monotonic() - started)
    log.info("%d bytes: pymavlink as QGC in %.1f s, MAVProxy in %.1f s", size, *took)
    return by_qgc, by_mavproxy


@pytest.mark.timeout(600)
@pytest.mark.vehicle(plan=PLAN, sim_args=["--start-at", f"{START_AT_S:g}"])
def test_a_flown_log_downloads_whole_and_holds_what_the_drivers_published(sim, tmp_path):
    logs = sim.state_dir / "logs"
    flight = Flight(sim.namespace, sim.ports.pymavlink)
    try:
        flight.gcs.connect(120)
        disarmed_ms = fly_the_leg(flight, 240)
        disarm(flight)
        wait_for(lambda: list(logs.glob("*.ulg")), 30, "the flight's log")
        (on_board,) = logs.glob("*.ulg")
        wait_for(lambda: not being_written(on_board), 30, "the log closed at the disarm")
        entries = list_logs(flight.gcs)
        assert list(entries) == [0] and entries[0].size == on_board.stat().st_size
        by_qgc, by_mavproxy = download_both(flight, sim.mavproxy_master, tmp_path, entries[0].size)
        for _ in range(10):  # the driver's counters of the last seconds
            flight.poll("HEARTBEAT")
        imu_counts = flight.imu_counts
    finally:
        flight.close()
    assert by_qgc == on_board.read_bytes()
    assert by_mavproxy == on_board.read_bytes()

    (tmp_path / "by_qgc.ulg").write_bytes(by_qgc)
    ulog = ULog(str(tmp_path / "by_qgc.ulg"))
    assert {d.name for d in ulog.data_list} >= TOPICS
    # The logger never holds a producer back: in a lockstep simulation running flat out
    # it may fall behind and lose samples, but each loss is a dropout and a warning that
    # names the channel, and the lost IMU samples are counted in below.
    losses = logged_losses(ulog)
    assert len(ulog.dropouts) == len(losses), losses
    imu_t = ulog.get_dataset("sensors_imu").data["timestamp"].astype(np.int64)
    # From before the arming (the samples kept from just before it) to the disarm.
    assert imu_t[0] <= START_AT_S * 1e6 and imu_t[-1] >= disarmed_ms * 1e3 - 1e6
    assert np.all(np.diff(imu_t) >= 0)
    imu_lost = [(t, n) for t, channel, n in losses if channel == "sensors/imu"]
    assert_every_imu_sample_logged(imu_t, imu_lost, imu_counts)
    assert_plausible(ulog)


def logged_losses(ulog: ULog) -> list[tuple[int, str, int]]:
    """(time of the first sample after the gap, channel, samples lost) per logger warning."""
    found = []
    for msg in ulog.logged_messages:
        if match := re.fullmatch(r"logger lost (\d+) samples of (\S+) .*", msg.message):
            found.append((int(msg.timestamp), match.group(2), int(match.group(1))))
    log.info("the logger's losses: %s", found)
    return found


def assert_every_imu_sample_logged(
    imu_t: np.ndarray, lost: list[tuple[int, int]], counts: list[tuple[int, int]]
) -> None:
    """Between two of the driver's counter reports, the log holds as many IMU samples as the
    driver published, less those it marks lost. A report at t counts samples stamped at or
    before t, and the next sample is stamped at t or later: samples stamped exactly t may
    fall on either side, and lost ones anywhere in their gap."""
    inside = [(t, n) for t, n in counts if imu_t[0] < t < imu_t[-1]]
    assert len(inside) >= 2, counts
    assert inside[-1][0] - inside[0][0] > 30e6, inside  # most of the flight
    before = [max(int(np.searchsorted(imu_t, t, "left")) - 1, 0) for t, _ in lost]
    gaps = [(int(imu_t[k]), t, n) for k, (t, n) in zip(before, lost, strict=True)]
    for (t1, n1), (t2, n2) in [*itertools.pairwise(inside), (inside[0], inside[-1])]:
        at_most = np.searchsorted(imu_t, t2, "right") - np.searchsorted(imu_t, t1, "left")
        at_least = np.searchsorted(imu_t, t2, "left") - np.searchsorted(imu_t, t1, "right")
        at_most += sum(n for a, b, n in gaps if a <= t2 and b >= t1)
        at_least += sum(n for a, b, n in gaps if a > t1 and b < t2)
        assert at_least <= n2 - n1 <= at_most, (t1, n1, t2, n2, at_least, at_most)


def assert_plausible(ulog: ULog) -> None:
    """The samples are finite and what a Cessna flying a short leg near Melbourne reads."""
    imu = ulog.get_dataset("sensors_imu").data
    accel = np.sqrt(imu["ax_m_s2"] ** 2 + imu["ay_m_s2"] ** 2 + imu["az_m_s2"] ** 2)
    gyro = np.sqrt(imu["gx_rad_s"] ** 2 + imu["gy_rad_s"] ** 2 + imu["gz_rad_s"] ** 2)
    assert np.all(np.isfinite(accel)) and np.all(np.isfinite(gyro))
    assert 7.0 < float(np.median(accel)) < 12.5 and accel.max() < 60.0
    assert gyro.max() < 5.0
    gps = ulog.get_dataset("sensors_gps").data
    fixed = gps["fix_type"] >= 3
    assert fixed.any()
    assert np.allclose(gps["lat_deg"][fixed], -37.91, atol=0.03)
    assert np.allclose(gps["lon_deg"][fixed], 145.14, atol=0.03)
    assert np.all(gps["ground_speed_m_s"][fixed] < 80)
    heading = ulog.get_dataset("sensors_compass").data["heading_rad"]
    assert np.all((heading >= 0) & (heading < 2 * math.pi))
    mag = ulog.get_dataset("sensors_mag").data
    field = np.sqrt(mag["mx_gauss"] ** 2 + mag["my_gauss"] ** 2 + mag["mz_gauss"] ** 2)
    assert np.all((field > 0.2) & (field < 1.0))  # Melbourne's 0.6 gauss, with the mount
    baro = ulog.get_dataset("sensors_baro").data["alt_rel_m"]
    assert np.all(np.isfinite(baro)) and baro.min() > -20 and baro.max() < 400
    nav = ulog.get_dataset("nav_state").data
    assert np.allclose(nav["lat_deg"][-100:], -37.91, atol=0.03)
