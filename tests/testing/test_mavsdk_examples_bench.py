"""MAVSDK-Python 4.1's examples' calls on the plug-in's bench vehicle, through its
``mavsdk_system`` fixture: all_params.py (every parameter, one set), telemetry.py (a
position), logfile_download.py (the log list), ftp_list_dir.py (a listing),
calibration.py (the gyro: the bench has no IMU, so a refusal with a reason) and the
multicopter-only offboard_velocity_ned.py (refused: the fixed wing has no Offboard
mode). Each call ends (an answer or a refusal) within a minute: none may hang.
"""

from __future__ import annotations

import asyncio

import pytest
from mavsdk.asyncio.plugins.calibration import CalibrationAsync
from mavsdk.asyncio.plugins.ftp import FtpAsync
from mavsdk.asyncio.plugins.log_files import LogFilesAsync
from mavsdk.asyncio.plugins.offboard import OffboardAsync
from mavsdk.asyncio.plugins.param import ParamAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.plugins.calibration import CalibrationError
from mavsdk.plugins.log_files import LogFilesError
from mavsdk.plugins.offboard import OffboardError, VelocityNedYaw

from companion.testing.bench import HOME

ANSWER_S = 60.0  # wall seconds for any one answer on a busy machine


async def _gyro(calibration: CalibrationAsync) -> str:
    async for result, _progress in calibration.calibrate_gyro():
        if result.name == "SUCCESS":
            return "SUCCESS"
    return "ended"


async def _first(stream):
    async for value in stream:
        return value


async def _refused(call) -> str:
    try:
        await asyncio.wait_for(call, ANSWER_S)
    except (CalibrationError, OffboardError) as exc:
        return exc.result.name
    return "accepted"


@pytest.mark.asyncio
@pytest.mark.timeout(420)
async def test_the_examples_calls_answer_on_the_bench(bench, mavsdk_system):
    bench.wait_ready()
    system = mavsdk_system
    param = ParamAsync(system)
    every = await asyncio.wait_for(param.get_all_params(), ANSWER_S)
    names = {p.name for p in every.float_params} | {p.name for p in every.int_params}
    assert {"ARMING_CHECK", "FS_GCS_TIMEOUT"} <= names, sorted(names)[:20]
    await asyncio.wait_for(param.set_param_float("FS_GCS_TIMEOUT", 7.0), ANSWER_S)
    assert await asyncio.wait_for(param.get_param_float("FS_GCS_TIMEOUT"), ANSWER_S) == 7.0

    position = await asyncio.wait_for(_first(TelemetryAsync(system).subscribe_position()), ANSWER_S)
    assert abs(position.latitude_deg - HOME[0]) < 0.01  # the replayed circle, 190 m across
    with pytest.raises(LogFilesError, match="NO_LOGFILES"):  # never armed: no log yet
        await asyncio.wait_for(LogFilesAsync(system).get_entries(), ANSWER_S)
    listing = await asyncio.wait_for(FtpAsync(system).list_directory("/"), ANSWER_S)
    assert "metadata" in [e.name for e in listing.entries]  # the component metadata's folder

    gyro = await _refused(_gyro(CalibrationAsync(system)))
    offboard = OffboardAsync(system)
    await offboard.set_velocity_ned(VelocityNedYaw(0.0, 0.0, 0.0, 0.0))
    started = await _refused(offboard.start())
    assert gyro not in ("accepted", "SUCCESS"), gyro
    assert started == "COMMAND_DENIED", started  # the vehicle's refusal, not MAVSDK's own
    assert bench.mode() == "LOITER"  # where the bench vehicle was
