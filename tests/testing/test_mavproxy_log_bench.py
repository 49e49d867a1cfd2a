"""MAVProxy's log commands (``log list``, ``log download``) on the plug-in's bench vehicle,
through its ``mavproxy_master`` connection string: the bench records a flight log from
its arming to its disarming, and MAVProxy fetches it whole; pyulog reads the copy, which
holds the bench's name and the replayed circle's GPS fixes."""

from __future__ import annotations

import numpy as np
import pytest
from pyulog import ULog

from companion.testing.bench import HOME
from tests.protocol.log_client import mavproxy_download
from tests.protocol.test_mavproxy import MavProxy
from tests.support.vehicle import wait_for

RECORD_S = 6.0  # vehicle seconds armed: a log of a few of the download's 90-byte packets


@pytest.mark.timeout(300)
def test_mavproxy_downloads_the_bench_flight_log(bench, tmp_path):
    bench.wait_ready()
    bench.arm()
    bench.run_until_time(bench.watcher.time_boot_s + RECORD_S)
    (on_board,) = bench.disarm()
    mavproxy = MavProxy(bench.mavproxy_master, tmp_path)

    def online() -> None:
        # Typed once MAVProxy has its parameters: its log list competes with nothing then.
        wait_for(lambda: "parameters to" in "".join(mavproxy.lines), 120, "MAVProxy's params")

    data = mavproxy_download(mavproxy, tmp_path, online, on_board.stat().st_size, 120)
    assert data == on_board.read_bytes()
    ulog = ULog(str(tmp_path / "flight.ulg"))
    assert ulog.msg_info_dict["vehicle_name"] == "bench"
    gps = ulog.get_dataset("sensors_gps").data
    assert len(gps["lat_deg"]) >= 5 * RECORD_S / 2  # the log's 5 Hz fixes, on a busy machine
    assert np.allclose(gps["lat_deg"], HOME[0], atol=0.01)  # the 190 m circle
    assert np.allclose(gps["lon_deg"], HOME[1], atol=0.01)
