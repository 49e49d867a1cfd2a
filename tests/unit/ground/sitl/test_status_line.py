"""The one-line status of ``companion sim`` (and each line of a fleet's)."""

from __future__ import annotations

from companion.control.modes import BY_MODE
from companion.messages import FlightMode, SimTruth, SystemHealth, VehicleStatus
from ground.sitl.session import mode_name, status_line


def test_the_line_names_the_mode_and_says_armed_height_speed_and_position():
    health = SystemHealth(t_us=0, flight_running=1)
    truth = SimTruth(t_us=12_300_000, alt_agl_m=123.4, airspeed_m_s=50.2,
                     lat_deg=-37.9105, lon_deg=145.134)  # fmt: skip
    mode = mode_name(VehicleStatus(t_us=0, mode=int(FlightMode.LOITER)))
    assert mode == BY_MODE[FlightMode.LOITER].name
    line = status_line(12_300_000, 24.1, health, truth, mode)
    for part in ("sim    12.3 s", "x 24.1", "ARMED", mode, "alt  123.4 m AGL", "air  50.2 m/s",
                 "-37.910500 145.134000"):  # fmt: skip
        assert part in line, (part, line)


def test_no_status_yet_shows_a_dash_and_disarmed():
    assert mode_name(None) == "-"
    assert "disarmed" in status_line(0, 0.0, None, None, mode_name(None))
