"""RTK corrections from the ground station reach the GPS receiver through the vehicle.

MAVSDK's Rtk plug-in sends each RTCM3 message as QGroundControl does for an RTK base
station on its computer: GPS_RTCM_DATA, in 180-byte fragments when longer. The link joins
them and the GPS driver writes each message whole to the receiver's port. The simulated
receiver (``--gps-receiver rtk-mavlink``) checks every frame's CRC and holds an RTK fix
while corrections are fresh (10 simulated seconds), float for their first 8 s, a plain 3-D
fix otherwise: MAVSDK sees the fix type go from 3-D through RTK float to RTK fixed, and
back to 3-D once they stop.
"""

from __future__ import annotations

import asyncio
import base64
import re

import pytest
from mavsdk.asyncio.plugins.rtk import RtkAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.plugins.rtk import RtcmData
from mavsdk.plugins.telemetry import FixType
from pyrtcm import RTCMMessage

from tests.sim.sim_run import sim_running
from tests.support.mavsdk_flight import ground_station, until

WAIT_S = 120.0


def rtcm3(kind: int, payload_bytes: int) -> bytes:
    """One RTCM3 frame of type ``kind`` with a payload of that many bytes (pyrtcm's CRC)."""
    payload = bytearray(payload_bytes)
    payload[0], payload[1] = kind >> 4, (kind & 0xF) << 4
    return RTCMMessage(payload=bytes(payload)).serialize()


# A base station's second: its position (1005), one message in three fragments and one of
# exactly two full ones (known whole only when the next message begins).
SECOND = [rtcm3(1005, 19), rtcm3(4072, 500), rtcm3(4072, 354)]


async def _send_corrections(rtk: RtkAsync, stop: asyncio.Event) -> None:
    while not stop.is_set():  # whole seconds only
        for frame in SECOND:
            await rtk.send_rtcm_data(RtcmData(base64.b64encode(frame).decode()))
        await asyncio.sleep(0.1)  # five a simulated second at the test's twice real time


async def _fix_types(port: int) -> dict:
    seen: dict = {}
    async with ground_station(port) as system:
        telemetry, rtk = TelemetryAsync(system), RtkAsync(system)
        # One stream from before the corrections on: a second one, subscribed once they flow,
        # could begin after the receiver's float seconds (a fraction of a wall second here).
        gps_info = telemetry.subscribe_gps_info()
        fix = await until(gps_info, lambda g: g.fix_type >= FixType.FIX_3D, "a fix", WAIT_S)
        seen["before"] = fix.fix_type
        stop = asyncio.Event()
        sender = asyncio.create_task(_send_corrections(rtk, stop))
        try:
            fixed, types = FixType.RTK_FIXED, []
            await until(
                gps_info,
                lambda g: types.append(g.fix_type) or g.fix_type == fixed,
                "RTK fixed",
                WAIT_S,
            )
            seen["on_the_way"] = types
            raw = await until(telemetry.subscribe_raw_gps(), lambda r: True, "GPS_RAW_INT", WAIT_S)
            seen["uncertainty_m"] = raw.horizontal_uncertainty_m
        finally:
            stop.set()
            await sender
        without = "the fix without corrections"
        after = await until(telemetry.subscribe_gps_info(), lambda g: g.fix_type != fixed,
                            without, WAIT_S)  # fmt: skip
        seen["after"] = after.fix_type
    return seen


@pytest.mark.timeout(600)
def test_corrections_sent_by_mavsdk_reach_the_receiver_whole_and_give_an_rtk_fix(tmp_path):
    # Twice real time, not as fast as the machine goes: the receiver's 8 float seconds then
    # last 4 wall seconds, time for MAVSDK to be told of them (at full speed they passed
    # in a third of a second, sometimes between two of its GPS reports).
    args = ("--aircraft", "c172p", "--gps-receiver", "rtk-mavlink", "--speed", "2")
    with sim_running(tmp_path, *args) as (port, proc, _truth):
        seen = asyncio.run(_fix_types(port))
    assert seen["before"] == FixType.FIX_3D
    # A float solution first, while the receiver resolves its ambiguities (8 s), as a real
    # rover's does; QGroundControl shows "3D RTK GPS Lock (float)", then "(fixed)".
    assert FixType.RTK_FLOAT in seen["on_the_way"], seen["on_the_way"]
    assert seen["uncertainty_m"] < 0.05  # h_acc: the fix's own 1.2 cm
    assert seen["after"] == FixType.FIX_3D
    out = proc.output()
    heard = re.search(r"RTCM3 from the vehicle: (\d+) messages \((.*)\), (\d+) bad", out)
    assert heard is not None, out[-3000:]
    assert int(heard[3]) == 0, heard[0]  # not one frame cut, joined wrongly or out of order
    counts = dict(re.findall(r"(\d+) x(\d+)", heard[2]))
    # Every message sent, each whole, and nothing else: the last 360-byte one alone is
    # still held, waiting for a next message to say it had ended.
    assert counts.keys() == {"1005", "4072"}, heard[0]
    assert int(counts["4072"]) == 2 * int(counts["1005"]) - 1, heard[0]
