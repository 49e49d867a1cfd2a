"""A telemetry radio that is not plugged in when the vehicle starts does not take the link
down: the ground station on UDP is served meanwhile, and the radio is taken when it comes."""

from __future__ import annotations

import os
import select
import time

from pymavlink.dialects.v20 import common as m

from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.support.configs import FAKE_NAV, TICKER, link, plugin, vehicle_config
from tests.support.pty import Pty


def _heartbeat_on(master: int, timeout_s: float) -> object | None:
    """The first HEARTBEAT the vehicle sends on the radio's other end."""
    parser = m.MAVLink(None)
    parser.robust_parsing = True
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        ready, _, _ = select.select([master], [], [], 0.2)
        if not ready:
            continue
        for msg in parser.parse_buffer(os.read(master, 4096)) or []:
            if msg.get_type() == "HEARTBEAT":
                return msg
    return None


def test_a_radio_plugged_in_after_start_joins_and_udp_flies_on_meanwhile(vehicle_factory, tmp_path):
    port = free_udp_port()
    radio = tmp_path / "ttyUSB0"  # nothing there yet
    endpoints = (f"udpin://127.0.0.1:{port}", f"serial://{radio}:57600")
    vehicle = vehicle_factory(
        vehicle_config(
            "radiotest",
            link(*endpoints),
            plugin("nav", FAKE_NAV),
            plugin("imu", TICKER),
            sysid=1,
            state_dir=tmp_path / "state",
        )
    )
    gcs = GroundStation(port)
    try:
        assert gcs.connect().type == m.MAV_TYPE_FIXED_WING  # served while the radio is missing
        pid = vehicle.wait_running("link")
        pty = Pty(radio)  # the adapter is plugged in
        try:
            beat = _heartbeat_on(pty.master, timeout_s=10.0)
            assert beat is not None and beat.type == m.MAV_TYPE_FIXED_WING
        finally:
            pty.vanish()
        row = vehicle.row("link")
        assert (row.pid, row.restarts) == (pid, 0)  # the link never died for it
    finally:
        gcs.close()
