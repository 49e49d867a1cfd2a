"""The PX4 names behind QGroundControl's Sensors, Power, Radio and Tuning pages: what a page
writes changes what the vehicle's own code then does (the stick scaling, the fuel gauge, the
control laws, the IMU's correction), and the arithmetic of the aliases that convert."""

from __future__ import annotations

import math

import pytest

from companion.control.flight.flight_params import control_params, flight_config
from companion.link.px4_compat import OS3000, PX4_PARAMS, VN100, sensor_ids, vehicle_facts
from companion.messages import Imu
from companion.params import ParamDecl, ParamError, ParamStore
from companion.params.alias import Alias
from companion.plugins.sensors.battery import BATTERY_PARAMS
from companion.sensors.battery_monitor import BatteryGauge, GaugeSettings, MonitorReading
from companion.sensors.imu_calibration import IMU_CAL_PARAMS, ImuCalibration
from companion.sensors.rc_channels import RC_PARAMS, centred, ranged, sticks

RC = {p.name: p.default for p in RC_PARAMS}
WHOLE = (*RC_PARAMS, *BATTERY_PARAMS, *control_params({}), *IMU_CAL_PARAMS)


def store(decls=WHOLE, plugins=None) -> ParamStore:
    return ParamStore(vehicle_facts((*decls, *PX4_PARAMS), 1, plugins or {}))


def test_a_time_constant_and_a_scaled_integrator_read_and_write_through_their_gains():
    own = (ParamDecl("P", 1.0, 0.0, 5.0), ParamDecl("D", 0.1, 0.0, 2.0), ParamDecl("I", 0.2))
    tc = ParamDecl("TC", 0.0, 0.0, alias=Alias(("P",), times="D", inverse=True))
    integ = ParamDecl("RATE_I", 0.0, 0.0, alias=Alias(("I",), times="D", divisor="P"))
    s = ParamStore((*own, tc, integ))
    assert s.get("TC") == pytest.approx(0.1) and s.get("RATE_I") == pytest.approx(0.02)
    assert s.write("TC", 0.4) == pytest.approx({"P": 0.25})  # D / TC
    assert s.get("RATE_I") == pytest.approx(0.2 * 0.1 / 0.25)
    assert s.write("RATE_I", 0.04) == pytest.approx({"I": 0.1})  # RATE_I · P / D
    assert sorted(s.linked("D")) == ["RATE_I", "TC"]
    with pytest.raises(ParamError, match="cannot be 0"):
        s.set("TC", 0.0)
    with pytest.raises(ParamError, match="outside"):
        s.set("TC", 0.01)  # P would be 10, beyond its range
    s.set("D", 0.0)
    assert s.get("TC") == 0.0
    with pytest.raises(ParamError, match="needs D above 0"):
        s.set("TC", 0.5)


def test_the_tuning_pages_names_set_the_control_laws_gains():
    s = store()
    assert (s.get("FW_RR_P"), s.get("FW_YR_P")) == (s.get("RLL_D"), s.get("YAW_DAMP"))
    assert s.get("FW_R_TC") == pytest.approx(s.get("RLL_D") / s.get("RLL_P"))
    s.set("FW_PR_P", 0.3)
    s.set("FW_P_TC", 0.5)
    s.set("FW_PR_I", 0.06)
    gains = flight_config(s.values).attitude
    assert (gains.pitch_d, gains.pitch_p, gains.pitch_i) == pytest.approx((0.3, 0.6, 0.12))
    s.set("FW_T_THR_DAMPING", 0.8)  # the law scales its throttle damping by 4
    s.set("FW_T_I_GAIN_PIT", 0.6)  # and its pitch integrator by 3: one integrator gain
    s.set("NPFG_PERIOD", 20.0)
    tecs = flight_config(s.values).tecs
    assert (tecs.throttle_damp, tecs.integ_gain) == pytest.approx((0.2, 0.2))
    assert s.get("FW_T_THR_INTEG") == pytest.approx(0.2) and s.get("NAVL1_PERIOD") == 20.0


def test_sensor_ids_name_the_sensors_the_config_runs():
    both = sensor_ids({"sensors.serial_imu": {"publish_mag": True}, "sensors.os3000": {}})
    assert both == {"CAL_ACC0_ID": VN100, "CAL_GYRO0_ID": VN100, "CAL_MAG0_ID": VN100,
                    "CAL_MAG1_ID": OS3000}  # fmt: skip
    compass_only = sensor_ids({"sensors.serial_imu": {"publish_mag": False}, "sensors.os3000": {}})
    assert (compass_only["CAL_MAG0_ID"], compass_only["CAL_MAG1_ID"]) == (OS3000, 0)
    assert set(sensor_ids({}).values()) == {0.0}
    assert VN100 < 2**24 and float(VN100) == VN100  # exact as a REAL32
    s = store(plugins={"sensors.serial_imu": {"publish_mag": True}})
    with pytest.raises(ParamError):
        s.set("CAL_GYRO0_ID", 0.0)  # a fact of the config, not a setting


def test_the_sensors_pages_offsets_are_the_imus_calibration():
    s = store()
    s.set("SENS_BOARD_Y_OFF", -2.0)
    s.set("CAL_GYRO0_ZOFF", 0.01)
    assert s.get("AHRS_TRIM_Y") == pytest.approx(math.radians(-2.0))
    cal = ImuCalibration.from_params(s.values)
    imu = Imu(ax_m_s2=9.80665 * math.sin(math.radians(-2.0)), ay_m_s2=0.0,
              az_m_s2=-9.80665 * math.cos(math.radians(2.0)), gz_rad_s=0.01)  # fmt: skip
    cal.correct(imu, None, cal.rotation)
    assert (imu.ax_m_s2, imu.az_m_s2, imu.gz_rad_s) == pytest.approx((0.0, -9.80665, 0.0))
    with pytest.raises(ParamError):
        s.set("SENS_BOARD_X_OFF", 15.0)  # ArduPilot's AHRS_TRIM range: 10 degrees


def test_the_power_pages_cells_give_what_is_left_without_a_capacity():
    s = store()
    s.set("BAT1_N_CELLS", 4.0)
    s.set("BAT1_V_EMPTY", 3.3)
    assert (s.get("BATT_CELLS"), s.get("BATT_CELL_EMPTY")) == (4.0, 3.3)
    v = s.values
    settings = GaugeSettings(cells=v["BATT_CELLS"], cell_full_v=v["BATT_CELL_FULL"],
                             cell_empty_v=v["BATT_CELL_EMPTY"])  # fmt: skip
    assert BatteryGauge(settings).update(MonitorReading(0, 15.0, 5.0)).remaining == (
        pytest.approx((3.75 - 3.3) / (4.2 - 3.3))
    )
    assert BatteryGauge(settings).update(MonitorReading(0, 17.2, 0.0)).remaining == 1.0
    counted = GaugeSettings(capacity_mah=1000, cells=4, cell_full_v=4.2, cell_empty_v=3.3)
    assert BatteryGauge(counted).update(MonitorReading(0, 13.0, 1.0)).remaining == 1.0
    assert math.isnan(BatteryGauge(GaugeSettings()).update(MonitorReading(0, 12, 1)).remaining)


def test_every_channel_is_calibrated_with_ardupilots_dead_zone():
    assert centred(1515, 1100, 1900, 1500, False, 20) == 0.0
    assert centred(1900, 1100, 1900, 1500, False, 20) == 1.0
    assert centred(1300, 1100, 1900, 1500, True, 20) == pytest.approx((480 - 300) / 380)
    assert ranged(1120, 1100, 1900, False, 30) == 0.0
    assert ranged(1100, 1100, 1900, True) == 1.0 and ranged(1900, 1100, 1900, True) == 0.0
    pulses = [1500] * 18
    pulses[15] = 1600  # roll on channel 16, dead zone 50 µs
    p = RC | {"RCMAP_ROLL": 16.0, "RC16_DZ": 50.0, "RC16_MIN": 1000.0, "RC16_MAX": 2000.0}
    assert sticks(pulses, p).roll == pytest.approx(50 / 450)
    s = store()
    s.set("RC_MAP_ROLL", 16.0)
    assert s.get("RCMAP_ROLL") == 16.0
    with pytest.raises(ParamError):
        s.set("RC_MAP_ROLL", 19.0)  # SBUS carries 18
