"""QGroundControl's own buttons find the modes they ask for, as 4.4.5 and 5 look them up.

QGroundControl 4.4.5 (src/Vehicle/StandardModes.cc) asks AVAILABLE_MODES index by index
(REQUEST_MESSAGE param2 = 1, 2, ...), names a mode that carries a standard mode after the
standard mode ("Safe Recovery", "Cruise", ...), hides Takeoff, Land, Orbit and Return from
the dropdown, and from then on its PX4 plug-in's buttons look their mode up by *name* in
that list (Pause: "Hold", Return: "Return", Start Mission: "Mission", Takeoff: "Takeoff",
Land: "Land"); a name it cannot find is only logged (``setFlightMode failed``).
QGroundControl 5 replaces its PX4 table by the list too, but its buttons ask by PX4's
custom_mode (PX4FirmwarePlugin::rtlFlightMode and the others), so the numbers must be PX4's.
"""

from __future__ import annotations

from companion.messages import FlightMode
from mavlink_dialect import companion as m
from tests.protocol.test_modes import station  # noqa: F401 - fixture
from tests.support.vehicle import wait_for

STANDARD_NAMES = {  # StandardModes::gotMessage, both 4.4.5 and 5
    m.MAV_STANDARD_MODE_POSITION_HOLD: "Position",
    m.MAV_STANDARD_MODE_ORBIT: "Orbit",
    m.MAV_STANDARD_MODE_CRUISE: "Cruise",
    m.MAV_STANDARD_MODE_ALTITUDE_HOLD: "Altitude",
    m.MAV_STANDARD_MODE_SAFE_RECOVERY: "Safe Recovery",
    m.MAV_STANDARD_MODE_MISSION: "Mission",
    m.MAV_STANDARD_MODE_LAND: "Land",
    m.MAV_STANDARD_MODE_TAKEOFF: "Takeoff",
}
BUTTONS = ("Takeoff", "Land", "Orbit", "Return", "VTOL Takeoff")  # never in the dropdown
# PX4's custom_mode for each button's mode (px4_custom_mode.h), what QGroundControl 5 asks.
PX4_AUTO = 4 << 16
QGC5_BY_NUMBER = {
    "Hold": PX4_AUTO | 3 << 24,
    "Mission": PX4_AUTO | 4 << 24,
    "Return": PX4_AUTO | 5 << 24,
    "Takeoff": PX4_AUTO | 2 << 24,
    "Land": PX4_AUTO | 6 << 24,
    "Manual": 1 << 16,
}


def qgc445_modes(gcs) -> tuple[dict[str, int], list[str]]:
    """(name → custom_mode, the dropdown's names) as QGroundControl 4.4.5 builds them."""
    table: dict[str, int] = {}
    dropdown: list[str] = []
    index, count = 1, 1
    while index <= count:
        gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AVAILABLE_MODES, index)
        assert gcs.ack(m.MAV_CMD_REQUEST_MESSAGE).result == m.MAV_RESULT_ACCEPTED
        msg = gcs.recv("AVAILABLE_MODES", 3.0, mode_index=index)
        name = STANDARD_NAMES.get(msg.standard_mode, msg.mode_name)
        table.setdefault(name, msg.custom_mode)
        hidden = msg.properties & m.MAV_MODE_PROPERTY_NOT_USER_SELECTABLE or name in BUTTONS
        if not hidden:
            dropdown.append(name)
        index, count = index + 1, msg.number_modes
    return table, dropdown


def _press(gcs, status, custom_mode: int, mode: FlightMode) -> None:
    """Vehicle::setFlightMode for the PX4 plug-in, then _setFlightModeAndValidate."""
    gcs.command(m.MAV_CMD_DO_SET_MODE, m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, custom_mode)
    assert gcs.ack(m.MAV_CMD_DO_SET_MODE).result == m.MAV_RESULT_ACCEPTED, mode
    gcs.recv("HEARTBEAT", 10.0, custom_mode=custom_mode)
    wait_for(lambda: status.get().mode == mode, 5.0, mode.name)


def test_qgc445_buttons_find_their_modes_by_name(station):  # noqa: F811 - fixture
    _, gcs, status = station(with_mission=True)
    table, dropdown = qgc445_modes(gcs)
    for name in ("Hold", "Return", "Mission", "Takeoff", "Land", "Manual"):
        assert name in table, f"setFlightMode failed, flightMode: {name!r}"
    assert "Safe Recovery" not in table and "Loiter" not in table
    assert {"Hold", "Mission", "Guided", "Manual", "Stabilized"} <= set(dropdown)
    assert not set(BUTTONS) & set(dropdown)
    # Return (its own button), Pause (Hold), Continue Mission: each flies that mode, and
    # the heartbeat then names it so that QGroundControl stops offering the same button.
    for name, mode in (("Return", FlightMode.RTL), ("Hold", FlightMode.LOITER),
                       ("Mission", FlightMode.MISSION), ("Return", FlightMode.RTL)):  # fmt: skip
        _press(gcs, status, table[name], mode)
        shown = {v: k for k, v in table.items()}[gcs.recv("HEARTBEAT", 5.0).custom_mode]
        assert shown == name
    # Takeoff on the ground, disarmed: the mode QGroundControl 5 sets before arming.
    _press(gcs, status, table["Takeoff"], FlightMode.TAKEOFF)


def test_qgc5_buttons_find_their_modes_by_px4_number(station):  # noqa: F811 - fixture
    _, gcs, status = station(with_mission=True)
    table, _ = qgc445_modes(gcs)
    for name, number in QGC5_BY_NUMBER.items():
        assert table[name] == number, name  # QGroundControl 5 names this number by our name
    _press(gcs, status, QGC5_BY_NUMBER["Return"], FlightMode.RTL)
    _press(gcs, status, QGC5_BY_NUMBER["Hold"], FlightMode.LOITER)
    # DO_SET_STANDARD_MODE SAFE_RECOVERY (what a standard-modes client sends) still returns.
    gcs.command(m.MAV_CMD_DO_SET_STANDARD_MODE, m.MAV_STANDARD_MODE_SAFE_RECOVERY)
    assert gcs.ack(m.MAV_CMD_DO_SET_STANDARD_MODE).result == m.MAV_RESULT_ACCEPTED
    wait_for(lambda: status.get().mode == FlightMode.RTL, 5.0, "Return")
