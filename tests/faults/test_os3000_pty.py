"""sensors.os3000 on a real pseudo-terminal: attitude and field flow, junk is counted."""

from __future__ import annotations

import math

import pytest

from tests.support.configs import plugin, vehicle_config
from tests.support.pty import Pty
from tests.support.vehicle import wait_for
from tests.unit.sensors.test_os3000 import sentence


@pytest.mark.timeout(60)
def test_compass_and_magnetometer_from_a_pty(vehicle_factory, tmp_path):
    pty = Pty(tmp_path / "ttyCompass")
    compass_plugin = plugin("compass", "sensors.os3000", device=pty.link)
    vehicle = vehicle_factory(vehicle_config("compass", compass_plugin))
    compass = vehicle.bus.queue_reader("sensors/compass")
    mag = vehicle.bus.queue_reader("sensors/mag")
    vehicle.wait_running("compass")
    got, fields = [], []
    line = sentence("C45.0P2.0R-1.0T21.0Mx200.0My0.0Mz-400.0") + "\r\n"

    def stream() -> bool:
        pty.write(line + "$C1P2*00\r\n" + line)
        got.extend(compass.take(0.3))
        fields.extend(mag.take(0.1))
        return len(got) >= 2 and bool(fields)

    wait_for(stream, 15, "compass readings")
    assert got[0].heading_rad == pytest.approx(math.radians(45.0))
    # The OS-5000's axes are x forward, y left, z up: Mz -400 mG is +0.4 G in body FRD.
    assert fields[0].mz_gauss == pytest.approx(0.4)
    wait_for(lambda: vehicle.row("compass").frames_bad >= 1, 5, "the bad sentence counted")
    pty.vanish()
