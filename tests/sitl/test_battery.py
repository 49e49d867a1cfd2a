"""What QGroundControl's battery indicator and sensor list show, in a lockstep flight.

The simulator emulates the power monitor (a 3S LiPo drawing current with the throttle);
a pymavlink ground station (QGroundControl's identity) reads SYS_STATUS and
BATTERY_STATUS as QGroundControl does, arms, flies the square plan, switches the monitor
off and on with MAV_CMD_INJECT_FAILURE, and brings the pack's charge under BATT_LOW_MAH.
"""

from __future__ import annotations

import time

import pytest
from pyulog import ULog

from companion.messages import FlightMode
from mavlink_dialect import companion as d
from tests.sitl.test_failsafes import PLAN, Station

WATCHED = ["HEARTBEAT", "STATUSTEXT", "MISSION_CURRENT", "COMMAND_ACK", "SYS_STATUS",
           "BATTERY_STATUS"]  # fmt: skip
SENSORS = {
    "accelerometer": d.MAV_SYS_STATUS_SENSOR_3D_ACCEL,
    "gyro": d.MAV_SYS_STATUS_SENSOR_3D_GYRO,
    "magnetometer": d.MAV_SYS_STATUS_SENSOR_3D_MAG,
    "barometer": d.MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE,
    "GPS": d.MAV_SYS_STATUS_SENSOR_GPS,
    "battery": d.MAV_SYS_STATUS_SENSOR_BATTERY,
}


pytestmark = pytest.mark.vehicle(plan=PLAN)


class BatteryStation(Station):
    """The failsafe tests' station, also keeping the newest SYS_STATUS and BATTERY_STATUS."""

    def __init__(self, station: Station) -> None:
        self.__dict__.update(station.__dict__)
        self.sys_status = None
        self.battery = None

    def pump(self, seconds: float) -> None:
        """As the failsafe station's, also taking SYS_STATUS and BATTERY_STATUS."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if self.beating and time.monotonic() >= self._next_beat:
                self.conn.mav.heartbeat_send(d.MAV_TYPE_GCS, d.MAV_AUTOPILOT_INVALID, 0, 0, 0)
                self._next_beat = time.monotonic() + 1.0
            msg = self.conn.recv_match(type=WATCHED, blocking=True, timeout=0.1)
            if msg is None or msg.get_srcSystem() != 1:
                continue
            kind = msg.get_type()
            if kind == "SYS_STATUS":
                self.sys_status = msg
            elif kind == "BATTERY_STATUS":
                self.battery = msg
            elif kind == "STATUSTEXT":
                self.texts.append(msg.text)
            elif kind == "MISSION_CURRENT":
                self.mission_seq = msg.seq
            elif kind == "COMMAND_ACK":
                self.acks[msg.command] = msg.result
            else:
                self.mode = msg.custom_mode
                if not self.modes or self.modes[-1] != self.mode:
                    self.modes.append(self.mode)

    def healthy(self, bits: int) -> bool:
        """Every one of ``bits`` healthy (not just any of them)."""
        s = self.sys_status
        return s is not None and s.onboard_control_sensors_health & bits == bits

    def amps(self) -> float:
        return -1.0 if self.battery is None else self.battery.current_battery / 100


@pytest.mark.timeout(300)
def test_battery_and_sensors_are_shown_true_and_low_battery_returns_home(sim):
    unit, off, ok = d.FAILURE_UNIT_SYSTEM_BATTERY, d.FAILURE_TYPE_OFF, d.FAILURE_TYPE_OK
    station = BatteryStation(Station(sim.pymavlink_url))
    try:
        every = sum(SENSORS.values())
        station.until(lambda: station.healthy(every), 60, "every sensor healthy")
        status = station.sys_status
        for name, bit in SENSORS.items():
            assert status.onboard_control_sensors_present & bit, f"{name} not listed"
            assert status.onboard_control_sensors_enabled & bit, f"{name} not enabled"
        assert 12_000 <= status.voltage_battery <= 12_700  # a full 3S pack at rest
        station.until(lambda: station.battery is not None, 10, "BATTERY_STATUS")
        on_ground = station.battery
        assert 0.0 < on_ground.current_battery / 100 < 2.0  # avionics only
        assert on_ground.battery_remaining >= 99
        assert on_ground.charge_state == d.MAV_BATTERY_CHARGE_STATE_OK

        station.fly_mission()
        station.until(lambda: station.amps() > 5.0, 120, "the motor drawing current")
        # Over 1 % of the pack, so the whole-percent figure QGC shows has moved.
        station.until(lambda: station.battery.current_consumed > 110, 120, "charge used")
        assert station.battery.battery_remaining < 100

        station.conn.mav.param_set_send(1, 1, b"SYS_FAILURE_EN", 1, d.MAV_PARAM_TYPE_REAL32)
        station.pump(0.5)
        assert station.acked(d.MAV_CMD_INJECT_FAILURE, unit, off) == d.MAV_RESULT_ACCEPTED
        battery_bit = SENSORS["battery"]
        station.until(lambda: not station.healthy(battery_bit), 60, "the battery shown unhealthy")
        assert station.sys_status.voltage_battery == 65535  # no stale figure shown as news
        assert station.healthy(SENSORS["GPS"])  # only the silent device turned red
        assert station.acked(d.MAV_CMD_INJECT_FAILURE, unit, ok) == d.MAV_RESULT_ACCEPTED
        station.until(lambda: station.healthy(battery_bit), 60, "the battery healthy again")

        # Low when less than this is left: a few mAh from now at cruise current.
        left = 10000 - station.battery.current_consumed - 5  # BATT_CAPACITY's default
        station.conn.mav.param_set_send(1, 1, b"BATT_LOW_MAH", left, d.MAV_PARAM_TYPE_REAL32)
        station.until(lambda: station.said("battery low"), 120, "told the battery is low")
        station.until(lambda: station.in_mode(FlightMode.RTL), 10, "returning home")
        station.until(
            lambda: station.battery.charge_state == d.MAV_BATTERY_CHARGE_STATE_LOW, 10, "LOW"
        )
    finally:
        station.conn.close()
    sim.close()  # stopped as at a terminal: the flight log is closed (and checked clean)
    # The flight log (one ULog per arming) records the gauge beside the other sensors.
    (log,) = (sim.state_dir / "logs").glob("*_armed.ulg")
    battery = ULog(str(log), ["sensors_battery"]).data_list[0].data
    assert battery["voltage_v"].max() > 11.5 and battery["current_a"].max() > 5.0
    assert battery["consumed_mah"][-1] > 10.0 and battery["level"][-1] == 1  # LOW
