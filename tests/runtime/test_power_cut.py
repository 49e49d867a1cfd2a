"""A power cut at any moment: every process of a running vehicle killed with SIGKILL while a
ground station writes parameters, missions, fences and rally points as fast as the vehicle
answers and the logger writes. Started again on the same state directory, the vehicle
serves what was stored (the last acknowledged write, or the one in flight at the cut),
and every flight log before the cut is whole: pyulog reads it to within a second of the cut.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import signal
import threading
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from pymavlink.dialects.v20 import common as m
from pyulog import ULog

from mavlink_dialect import companion as d
from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.support.configs import FAKE_NAV, TICKER, link, plugin, vehicle_config
from tests.support.vehicle import Vehicle, wait_for

log = logging.getLogger(__name__)
CUTS = 2
FLUSH_S = 1.0  # the logger's default: a cut may lose this much
MARGIN_S = 0.3  # the logger's read period and a busy machine (as test_flight_log's)
HOME = (-37.9105, 145.134)
PARAM = "SR_ATTITUDE"  # stored by the link in params.json, 0-100
TYPES = (d.MAV_MISSION_TYPE_MISSION, d.MAV_MISSION_TYPE_FENCE, d.MAV_MISSION_TYPE_RALLY)
REL = d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT

Item = tuple[int, float, int, int]  # command, param1, lat and lon in 1e-7 degrees


def items_for(mission_type: int, tag: int) -> list[Item]:
    """A list of ``mission_type`` whose positions say which write it was (``tag``)."""
    lat0, lon0 = round(HOME[0] * 1e7) + tag * 100, round(HOME[1] * 1e7)
    if mission_type == d.MAV_MISSION_TYPE_FENCE:  # a square around home
        corners = [(-1, -1), (-1, 1), (1, 1), (1, -1)]
        cmd = d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION
        return [(cmd, 4.0, lat0 + a * 50_000, lon0 + b * 50_000) for a, b in corners]
    if mission_type == d.MAV_MISSION_TYPE_RALLY:
        return [(d.MAV_CMD_NAV_RALLY_POINT, 0.0, lat0 + 1000 * i, lon0) for i in range(2)]
    count = 2 + tag % 5  # the length changes too
    first = [(d.MAV_CMD_NAV_TAKEOFF, 0.0, lat0, lon0)]
    return first + [(d.MAV_CMD_NAV_WAYPOINT, 0.0, lat0 + 2000 * i, lon0) for i in range(1, count)]


def upload(gcs: GroundStation, mission_type: int, items: list[Item], timeout_s: float) -> bool:
    """Upload as QGroundControl does; whether the vehicle accepted it."""
    gcs.mav.mission_count_send(1, 1, len(items), mission_type)
    for _ in items:
        req = gcs.recv(["MISSION_REQUEST_INT", "MISSION_REQUEST"], timeout_s)
        cmd, p1, lat, lon = items[req.seq]
        gcs.mav.mission_item_int_send(
            1, 1, req.seq, REL, cmd, 0, 1, p1, 0, 0, 0, lat, lon, 50, mission_type
        )
    return gcs.recv("MISSION_ACK", timeout_s).type == d.MAV_MISSION_ACCEPTED


def download(gcs: GroundStation, mission_type: int) -> list[Item]:
    gcs.mav.mission_request_list_send(1, 1, mission_type)
    count = gcs.recv("MISSION_COUNT", mission_type=mission_type).count
    got = []
    for seq in range(count):
        gcs.mav.mission_request_int_send(1, 1, seq, mission_type)
        it = gcs.recv("MISSION_ITEM_INT", seq=seq, mission_type=mission_type)
        got.append((it.command, it.param1, it.x, it.y))
    gcs.mav.mission_ack_send(1, 1, d.MAV_MISSION_ACCEPTED, mission_type)
    return got


def read_param(gcs: GroundStation) -> float:
    gcs.mav.param_request_read_send(1, 1, PARAM.encode(), -1)
    return gcs.recv("PARAM_VALUE", param_id=PARAM).param_value


@dataclass
class Written:
    """Per store: the last content the vehicle acknowledged, and one sent but unanswered."""

    acked: dict[object, object] = field(default_factory=dict)
    in_flight: dict[object, object] = field(default_factory=dict)

    def allowed(self, key: object) -> list[object]:
        return [v for v in (self.acked.get(key), self.in_flight.get(key)) if v is not None]


def write_until_cut(gcs: GroundStation, written: Written, cut: threading.Event, tag: int) -> int:
    """Parameter sets and uploads of every type, round after round, until the cut; the
    number the vehicle acknowledged."""
    writes = 0
    while not cut.is_set():
        tag += 1
        value = float(tag % 97 + 1)
        written.in_flight[PARAM] = value
        try:
            gcs.mav.param_set_send(1, 1, PARAM.encode(), value, m.MAV_PARAM_TYPE_REAL32)
            if gcs.recv("PARAM_VALUE", 3, param_id=PARAM).param_value == value:
                written.acked[PARAM], written.in_flight[PARAM] = value, None
                writes += 1
            mission_type = TYPES[tag % 3]
            items = items_for(mission_type, tag)
            written.in_flight[mission_type] = items
            if upload(gcs, mission_type, items, 3):
                written.acked[mission_type], written.in_flight[mission_type] = items, None
                writes += 1
        except AssertionError:  # no answer: the cut came
            break
    return writes


def start(vehicle_factory, state: Path) -> tuple[Vehicle, GroundStation]:
    port = free_udp_port()
    vehicle = vehicle_factory(
        vehicle_config(
            "powercut",
            link(f"udpin://127.0.0.1:{port}"),
            plugin("nav", FAKE_NAV),
            plugin("imu", TICKER, rate_hz=100.0),
            plugin("logger", "system.logger", from_boot=True, flush_s=FLUSH_S),
            sysid=1,
            state_dir=state,
        )
    )
    gcs = GroundStation(port)
    gcs.connect()
    return vehicle, gcs


def power_cut(vehicle: Vehicle) -> None:
    """Every process of the vehicle at once: none can close a file."""
    for pid in vehicle.all_pids():
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    assert vehicle.proc is not None
    vehicle.proc.wait(timeout=10)


def imu_stamps(path: Path) -> list[int]:
    ulog = ULog(str(path))
    return [int(t) for t in ulog.get_dataset("sensors_imu").data["timestamp"]]


def wait_new_log(logs: Path, sealed: dict[Path, str]) -> None:
    """Until a log of the running vehicle's (none of ``sealed``) is in view."""
    wait_for(lambda: any(p not in sealed for p in logs.glob("*.ulg")), 30, "a new log")


def check_stored(gcs: GroundStation, written: Written) -> None:
    """The restarted vehicle serves the last acknowledged content or the one in flight."""
    assert read_param(gcs) in written.allowed(PARAM)
    for mission_type in TYPES:
        assert download(gcs, mission_type) in written.allowed(mission_type), mission_type


@pytest.mark.timeout(600)
def test_a_power_cut_mid_write_leaves_every_store_and_log_readable(vehicle_factory, tmp_path):
    state = tmp_path / "state"
    logs = state / "logs"
    written = Written(acked={PARAM: 10.0, **{t: [] for t in TYPES}})  # the defaults
    sealed: dict[Path, str] = {}  # the logs of earlier runs, and their content at the cut
    tag = 0
    vehicle, gcs = start(vehicle_factory, state)
    for cut_no in range(1, CUTS + 1):
        imu = vehicle.bus.queue_reader("sensors/imu")  # a full queue keeps its newest
        # The log of this run is on disk and growing before the writes begin.
        wait_new_log(logs, sealed)
        cut = threading.Event()
        newest_us = [0]

        def cut_power(v=vehicle, c=cut, reader=imu, newest=newest_us) -> None:
            for sample in reader.drain():  # the newest IMU sample published before the cut
                newest[0] = max(newest[0], int(sample.t_us))
            pids = v.all_pids()
            c.set()
            for pid in pids:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(pid, signal.SIGKILL)

        timer = threading.Timer(2.0 + 0.7 * cut_no, cut_power)
        timer.start()
        tag += 1000
        writes = write_until_cut(gcs, written, cut, tag)
        timer.join()
        power_cut(vehicle)  # whatever the timer's kill missed
        gcs.close()
        log.info("cut %d: after %d acknowledged writes", cut_no, writes)
        assert writes >= 4, "the cut came while the ground station was writing"

        # Every log before the cut reads whole; this run's ends within a second of the cut.
        files = sorted(logs.glob("*.ulg"))
        assert len(files) == cut_no
        for path in files:
            if path in sealed:
                assert hashlib.sha256(path.read_bytes()).hexdigest() == sealed[path]
            stamps = imu_stamps(path)
            assert stamps == sorted(stamps) and len(stamps) > 100, path.name
        last = files[-1]
        lost_s = (newest_us[0] - imu_stamps(last)[-1]) / 1e6
        log.info("cut %d: %s ends %.3f s before the cut", cut_no, last.name, lost_s)
        assert lost_s <= FLUSH_S + MARGIN_S, lost_s
        sealed[last] = hashlib.sha256(last.read_bytes()).hexdigest()

        vehicle, gcs = start(vehicle_factory, state)  # the same state directory
        check_stored(gcs, written)
    gcs.close()
    assert all(written.acked[t] for t in TYPES), "each kind of list was stored"
    # The last run's log is in view once its header is on disk, whenever its logger started.
    wait_new_log(logs, sealed)
    assert not list(state.rglob(".*.part")), "no log left hidden"
