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


def test_generic_reads_a_main_mode_alone_as_arduplane_circle_and_cruise_too():
    # MAVProxy's `mode CIRCLE` and `mode CRUISE` (ArduPlane 1 and 7): not PX4's Manual and
    # Stabilized, which they had been taken for.
    assert decode_set_mode(CUSTOM, 1, 0, reporting_px4=False) == FlightMode.LOITER
    assert decode_set_mode(CUSTOM, 7, 0, reporting_px4=False) == FlightMode.POSITION
    assert decode_set_mode(CUSTOM, 3, 0, reporting_px4=False) is None  # TRAINING
    assert decode_set_mode(CUSTOM, 4, 3, reporting_px4=False) == FlightMode.LOITER  # PX4 pair


def test_px4_profile_keeps_px4_main_modes():
    assert decode_set_mode(CUSTOM, 1, 0, reporting_px4=True) == FlightMode.MANUAL
    assert decode_set_mode(CUSTOM, 7, 0, reporting_px4=True) == FlightMode.STABILIZED
