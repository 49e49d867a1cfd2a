"""The low-battery failsafe: announced once per level, acted on once while flying."""

from __future__ import annotations

from companion.control.battery_failsafe import BATTERY_FS_PARAMS, BatteryFailsafe
from companion.messages import BatteryLevel, FlightMode

DEFAULTS = {p.name: p.default for p in BATTERY_FS_PARAMS}


def test_low_in_flight_returns_home_once_and_critical_acts_again():
    fs = BatteryFailsafe(dict(DEFAULTS))
    assert fs.step(BatteryLevel.OK, True) == []
    (low,) = fs.step(BatteryLevel.LOW, True)
    assert low.mode == FlightMode.RTL and "battery low" in low.text
    assert fs.step(BatteryLevel.LOW, True) == []  # the operator may take it back
    (critical,) = fs.step(BatteryLevel.CRITICAL, True)
    assert critical.mode == FlightMode.RTL and "critical" in critical.text
    assert fs.step(BatteryLevel.CRITICAL, True) == []


def test_on_the_ground_it_warns_then_acts_once_airborne():
    fs = BatteryFailsafe(dict(DEFAULTS))
    (said,) = fs.step(BatteryLevel.LOW, False)
    assert said.mode is None and said.text == "Battery low"
    assert fs.step(BatteryLevel.LOW, False) == []
    (acted,) = fs.step(BatteryLevel.LOW, True)
    assert acted.mode == FlightMode.RTL


def test_warn_only_and_garbage_levels():
    fs = BatteryFailsafe(dict(DEFAULTS, BATT_FS_LOW_ACT=0.0))
    (said,) = fs.step(BatteryLevel.LOW, True)
    assert said.mode is None
    assert fs.step(None, True) == [] and fs.step(7, True) == []
