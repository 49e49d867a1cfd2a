"""DO_SET_MODE as MAVSDK sends it: PX4 main modes; Offboard refused, not read as FBWB."""

from __future__ import annotations

from companion.control.modes import PX4_MAIN_OFFBOARD, decode_set_mode
from companion.messages import FlightMode
from mavlink_dialect import companion as d

CUSTOM = d.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED


def test_mavsdk_offboard_start_is_refused_while_reporting_px4():
    assert decode_set_mode(CUSTOM, PX4_MAIN_OFFBOARD, 0, reporting_px4=True) is None


def test_arduplane_numbers_still_read_where_px4_has_no_such_mode():
    assert decode_set_mode(CUSTOM, 10, 0, reporting_px4=False) == FlightMode.MISSION  # AUTO
    assert decode_set_mode(CUSTOM, 6, 0, reporting_px4=False) == FlightMode.ALTITUDE  # FBWB
    assert decode_set_mode(CUSTOM, 11, 0, reporting_px4=True) == FlightMode.RTL
