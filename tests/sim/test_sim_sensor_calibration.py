"""QGroundControl's gyro and level calibrations on the simulated aircraft, standing still
on the runway with its engine idling (issue 42.4).

The sensor model shook the airframe with the propeller's cruise-power vibration whatever
the throttle: standing still the IMU's accelerometers spread by 0.35 m/s², over the 0.3
m/s² a calibration allows, and both calibrations always failed ("the aircraft moved, hold
it still"). At idle the vibration is now the propeller's at idle speed. Sent as
QGroundControl's Sensors page sends them (tests/protocol/test_qgc_sensor_calibration.py
has the bench).

JSBSim drops the aircraft onto its gear at the start: it rocks for about 5 s of its time
(2° of pitch). A calibration asked then fails, rightly; as a person would, the test waits
for Ready To Fly (pre-arm passing, which needs the navigator aligned on a still aircraft).
"""

from __future__ import annotations

import math

import pytest

from mavlink_dialect import companion as m
from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.protocol.test_qgc_sensor_calibration import PROGRESS, calibrate, param
from tests.sim.sim_run import finish, start_sim
from tests.support.vehicle import wait_for


@pytest.mark.timeout(300)
def test_gyro_and_level_calibrations_pass_on_the_idling_aircraft(tmp_path):
    port = free_udp_port()
    proc, namespace, _truth = start_sim(
        tmp_path, f"udpin://127.0.0.1:{port}", "--aircraft", "c172p", "--duration", "900",
        "--speed", "1",  # as a person runs it (the last --speed counts); max outruns the link
    )  # fmt: skip
    gcs = GroundStation(port)
    try:
        gcs.connect(120.0)
        # As a person would, once QGroundControl shows Ready To Fly.
        gcs.recv("SCALED_IMU", 120.0)
        healthy = m.MAV_SYS_STATUS_PREARM_CHECK
        wait_for(lambda: gcs.recv("SYS_STATUS", 5.0).onboard_control_sensors_health & healthy,
                 120, "pre-arm checks passing")  # fmt: skip
        result, texts = calibrate(gcs, 1, 0, 0, 0, 0, 0, 0)  # gyro
        assert result == m.MAV_RESULT_ACCEPTED, texts
        assert texts == ["calibration started: 2 gyro", *PROGRESS, "calibration done: gyro"]
        offsets = [param(gcs, f"INS_GYROFFS_{axis}") for axis in "XYZ"]
        # The model's turn-on bias is 0.003 rad/s (1 σ) a gyro: what was found is that size.
        assert 0.0 < max(abs(v) for v in offsets) < 0.015, offsets
        result, texts = calibrate(gcs, 0, 0, 0, 0, 2, 0, 0)  # level horizon
        assert result == m.MAV_RESULT_ACCEPTED, texts
        assert texts == ["calibration started: 2 level", *PROGRESS, "calibration done: level"]
        # The c172p stands on its tricycle gear within a degree or two of level.
        trims = [math.degrees(param(gcs, f"AHRS_TRIM_{axis}")) for axis in "XY"]
        assert max(abs(v) for v in trims) < 3.0, trims
    finally:
        gcs.conn.close()
        proc.terminate()
        finish(proc, namespace, 60)
