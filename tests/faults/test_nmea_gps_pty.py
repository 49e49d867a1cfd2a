"""sensors.nmea_gps on a real pseudo-terminal: fixes flow, junk is counted, a vanished
device is reopened when it comes back."""

from __future__ import annotations

import pytest

from tests.support.configs import plugin, vehicle_config
from tests.support.nmea import gga, rmc
from tests.support.pty import Pty
from tests.support.vehicle import wait_for

LAT, LON = -37.9105, 145.134


@pytest.mark.timeout(90)
def test_fixes_junk_and_a_device_that_vanishes_and_returns(vehicle_factory, tmp_path):
    device = tmp_path / "ttyGPS"
    pty = Pty(device)
    gps = plugin("gps", "sensors.nmea_gps", device=f"serial://{device}:9600")
    vehicle = vehicle_factory(vehicle_config("gps", gps))
    fixes = vehicle.bus.queue_reader("sensors/gps")
    vehicle.wait_running("gps")
    got = []

    def epoch(second: int, alt: float) -> str:
        time = f"1200{second:02d}.00"
        return (
            rmc(time, "231126", LAT, LON, 30.0, 45.0) + "\r\n" + gga(time, LAT, LON, alt) + "\r\n"
        )

    def stream() -> bool:  # a GPS talks all the time; the port may open after we start
        got.clear()
        pty.write(epoch(0, 100.0) + "garbage\r\n$GPGGA,broken*00\r\n" + epoch(1, 102.0))
        got.extend(fixes.take(0.3))
        got.extend(fixes.take(0.1))
        return len(got) >= 2

    wait_for(stream, 15, "two fixes")
    assert got[0].lat_deg == pytest.approx(LAT, abs=1e-9) and got[1].alt_msl_m == 102.0
    assert got[1].vd_m_s == pytest.approx(-2.0)
    wait_for(lambda: vehicle.row("gps").frames_bad >= 2, 5, "the junk counted")

    pty.vanish()
    pty = Pty(device)  # plugged back in: a new device at the same path
    restarts = vehicle.row("gps").restarts
    got.clear()

    def resend() -> bool:
        pty.write(epoch(5, 110.0))
        got.extend(fixes.take(0.3))
        return bool(got)

    wait_for(resend, 20, "fixes from the reopened device")
    assert got[-1].alt_msl_m == 110.0
    assert vehicle.row("gps").restarts == restarts, "reopened in place, not by a crash"
    pty.vanish()
