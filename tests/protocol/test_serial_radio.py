"""A MAVLink radio on a serial port (a pty here) pulled out and plugged back in while the
vehicle runs: its HEARTBEAT comes back on the radio, the ground station on UDP is served
throughout, and the link neither restarts nor spins while the radio is gone."""

from __future__ import annotations

import contextlib
import logging
import os
import time

import pytest

from mavlink_dialect import companion as dialect
from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.support.configs import FAKE_NAV, link, plugin, vehicle_config
from tests.support.pty import Pty
from tests.support.vehicle import wait_for

log = logging.getLogger(__name__)


def radio_heartbeat(pty: Pty, parser) -> bool:
    """Whether a HEARTBEAT of the vehicle arrived on the radio since the last look."""
    os.set_blocking(pty.master, False)
    try:
        data = os.read(pty.master, 4096)
    except (BlockingIOError, OSError):
        return False
    with contextlib.suppress(Exception):
        msgs = parser.parse_buffer(data) or []
        return any(m.get_type() == "HEARTBEAT" and m.get_srcSystem() == 1 for m in msgs)
    return False


@pytest.mark.timeout(300)
def test_a_radio_pulled_out_and_plugged_back_in_speaks_again(vehicle_factory, tmp_path):
    device = tmp_path / "ttyUSB0"
    pty = Pty(device)
    port = free_udp_port()
    vehicle = vehicle_factory(
        vehicle_config(
            "radio",
            link(f"udpin://127.0.0.1:{port}", f"serial://{device}:57600"),
            plugin("nav", FAKE_NAV),
            sysid=1,
            state_dir=tmp_path / "state",
        )
    )
    gcs = GroundStation(port)
    gcs.connect()
    parser = dialect.MAVLink(None)
    parser.robust_parsing = True
    wait_for(lambda: radio_heartbeat(pty, parser), 30, "a HEARTBEAT on the radio")

    pty.vanish()  # the USB adapter pulled out
    gone_at = time.monotonic()
    gcs.recv("HEARTBEAT", 10)  # the ground station on UDP is still served
    time.sleep(3.0)  # two health tables while the radio is gone
    cpu = vehicle.row("link").cpu_pct
    log.info("link CPU with the radio gone: %.1f %% of a core", cpu)
    assert cpu < 15.0, "the link spins on a vanished device (27 % before it closed it)"

    pty = Pty(device)  # plugged back in, at the same path
    back_at = time.monotonic()
    parser = dialect.MAVLink(None)
    parser.robust_parsing = True
    wait_for(lambda: radio_heartbeat(pty, parser), 30, "a HEARTBEAT on the radio again")
    log.info(
        "radio back %.2f s after the re-plug (%.1f s after it went)",
        time.monotonic() - back_at,
        time.monotonic() - gone_at,
    )
    assert vehicle.row("link").restarts == 0
    gcs.recv("HEARTBEAT", 10)
    gcs.close()
    pty.vanish()
