"""Telemetry streams never break on extreme or missing bus values."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from companion.link.codec import new_encoder, new_parser
from companion.link.snapshot import Snapshot
from companion.link.telemetry import STREAMS
from companion.messages import (
    Battery,
    ControlStatus,
    GpsFix,
    Imu,
    NavFlags,
    NavState,
    RangeReading,
)

floats = st.floats(allow_nan=True, allow_infinity=True, width=64)


@settings(max_examples=400, deadline=None)
@given(
    ax=floats, gz=floats, roll=floats, lat=floats, vn=floats, alt=floats, speed=floats, yaw=floats
)
def test_every_stream_encodes_whatever_the_sensors_say(ax, gz, roll, lat, vn, alt, speed, yaw):
    mav = new_encoder(1)
    nav = NavState(t_us=1, roll_rad=roll, yaw_rad=yaw, lat_deg=lat, vn_m_s=vn, alt_msl_m=alt)
    nav.flags = int(NavFlags.ATTITUDE_VALID | NavFlags.POSITION_VALID | NavFlags.VELOCITY_VALID)
    gps = GpsFix(t_us=1, lat_deg=lat, alt_msl_m=alt, ground_speed_m_s=speed, hdop=speed)
    gps.eph_m, gps.epv_m = speed, ax
    gps.course_rad = yaw
    snap = Snapshot(time_boot_ms=5, nav=nav, imu=Imu(t_us=1, ax_m_s2=ax, gz_rad_s=gz), gps=gps)
    snap.control = ControlStatus(t_us=1, airspeed_m_s=speed, throttle=roll)
    snap.battery = Battery(t_us=1, voltage_v=alt, current_a=vn, consumed_mah=lat, remaining=ax)
    snap.rangefinder = RangeReading(
        t_us=1, distance_m=alt, min_distance_m=ax, max_distance_m=gz, valid=1, signal_quality=50
    )
    for stream in STREAMS.values():
        msg = stream.build(mav, snap)  # must not raise, whatever the values
        if msg is not None:
            (decoded,) = new_parser().parse_buffer(msg.pack(mav))
            assert decoded.get_type() == stream.name


def test_vfr_hud_shows_the_estimated_airspeed_and_the_throttle_in_flight():
    mav = new_encoder(1)
    nav = NavState(t_us=1, vn_m_s=20.0, ve_m_s=0.0, alt_msl_m=150.0)
    snap = Snapshot(nav=nav)
    on_ground = STREAMS[74].build(mav, snap)  # no flight controller: ground speed, idle
    assert (on_ground.airspeed, on_ground.groundspeed, on_ground.throttle) == (20.0, 20.0, 0)
    snap.control = ControlStatus(t_us=1, airspeed_m_s=24.5, throttle=0.62)
    flying = STREAMS[74].build(mav, snap)  # into a 4.5 m/s head wind
    assert (flying.airspeed, flying.groundspeed, flying.throttle) == (24.5, 20.0, 62)


def test_gps_raw_int_says_an_rtk_fix_and_its_accuracy_in_millimetres():
    """QGroundControl's GPS indicator shows the lock ("RTK Fixed") and MAVSDK's RawGps the
    horizontal and vertical uncertainty."""
    fix = GpsFix(t_us=1, lat_deg=-37.9, lon_deg=145.1, alt_msl_m=80.0, hdop=0.6, satellites=20)
    fix.fix_type, fix.eph_m, fix.epv_m = 6, 0.012, float("nan")
    msg = STREAMS[24].build(new_encoder(1), Snapshot(gps=fix))
    assert (msg.fix_type, msg.eph, msg.h_acc, msg.v_acc) == (6, 60, 12, 0)  # v_acc 0: not known


def _sensors_at(t_us: int) -> dict:
    from companion.messages import Baro, Battery, Compass

    gps = GpsFix(t_us=t_us, fix_type=3)
    battery = Battery(t_us=t_us, voltage_v=12.31, current_a=14.5, consumed_mah=250.4)
    battery.remaining = 0.886
    imu, compass, baro = Imu(t_us=t_us), Compass(t_us=t_us), Baro(t_us=t_us)
    return {"imu": imu, "compass": compass, "baro": baro, "gps": gps, "battery": battery}


def test_sys_status_lists_every_sensor_in_use_healthy_while_its_samples_are_recent():
    from mavlink_dialect import companion as d

    mav = new_encoder(1)
    snap = Snapshot(now_us=10_000_000, **_sensors_at(9_900_000))
    every = (
        d.MAV_SYS_STATUS_SENSOR_3D_ACCEL | d.MAV_SYS_STATUS_SENSOR_3D_GYRO
        | d.MAV_SYS_STATUS_SENSOR_3D_MAG | d.MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE
        | d.MAV_SYS_STATUS_SENSOR_GPS | d.MAV_SYS_STATUS_SENSOR_BATTERY
    )  # fmt: skip
    fresh = STREAMS[d.MAVLINK_MSG_ID_SYS_STATUS].build(mav, snap)
    assert fresh.onboard_control_sensors_present & every == every
    assert fresh.onboard_control_sensors_enabled & every == every
    assert fresh.onboard_control_sensors_health & every == every
    assert (fresh.voltage_battery, fresh.current_battery, fresh.battery_remaining) == (
        12310,
        1450,
        89,
    )
    snap.now_us = 12_000_000  # 2.1 s later by the vehicle clock, nothing new from any sensor
    stale = STREAMS[d.MAVLINK_MSG_ID_SYS_STATUS].build(mav, snap)
    assert stale.onboard_control_sensors_present & every == every
    assert stale.onboard_control_sensors_health & every == 0
    assert (stale.voltage_battery, stale.current_battery, stale.battery_remaining) == (
        65535,
        -1,
        -1,
    )


def test_battery_status_reports_the_pack_and_its_charge_state():
    from companion.messages import BatteryLevel
    from mavlink_dialect import companion as d

    mav = new_encoder(1)
    snap = Snapshot(now_us=1_000_000, **_sensors_at(1_000_000))
    msg = STREAMS[d.MAVLINK_MSG_ID_BATTERY_STATUS].build(mav, snap)
    assert msg.voltages[0] == 12310 and set(msg.voltages[1:]) == {65535}
    assert (msg.current_battery, msg.current_consumed, msg.battery_remaining) == (1450, 250, 89)
    assert msg.charge_state == d.MAV_BATTERY_CHARGE_STATE_OK
    snap.battery.level = BatteryLevel.LOW
    low = STREAMS[d.MAVLINK_MSG_ID_BATTERY_STATUS].build(mav, snap)
    assert low.charge_state == d.MAV_BATTERY_CHARGE_STATE_LOW
    sys_status = STREAMS[d.MAVLINK_MSG_ID_SYS_STATUS].build(mav, snap)
    assert not sys_status.onboard_control_sensors_health & d.MAV_SYS_STATUS_SENSOR_BATTERY
    assert STREAMS[d.MAVLINK_MSG_ID_BATTERY_STATUS].build(mav, Snapshot()) is None


def test_sys_status_lists_the_rc_receiver_healthy_while_its_radio_is_heard():
    from companion.messages import PilotFlags, PilotInput
    from mavlink_dialect import companion as d

    mav = new_encoder(1)
    rc_bit = d.MAV_SYS_STATUS_SENSOR_RC_RECEIVER
    sys_status = STREAMS[d.MAVLINK_MSG_ID_SYS_STATUS]
    no_receiver = sys_status.build(mav, Snapshot(now_us=10_000_000))
    assert no_receiver.onboard_control_sensors_present & rc_bit == 0
    snap = Snapshot(now_us=10_000_000, rc=PilotInput(t_us=9_950_000, throttle=0.5))
    heard = sys_status.build(mav, snap)
    assert heard.onboard_control_sensors_present & rc_bit
    assert heard.onboard_control_sensors_enabled & rc_bit
    assert heard.onboard_control_sensors_health & rc_bit
    for flags in (PilotFlags.FAILSAFE, PilotFlags.THROTTLE_LOW):  # the receiver's failsafe
        snap.rc = PilotInput(t_us=9_950_000, flags=int(flags))
        failsafe = sys_status.build(mav, snap)
        assert failsafe.onboard_control_sensors_present & rc_bit
        assert failsafe.onboard_control_sensors_health & rc_bit == 0
    snap.rc = PilotInput(t_us=9_950_000, throttle=0.5)
    snap.now_us = 11_500_000  # the receiver silent for 1.55 s
    silent = sys_status.build(mav, snap)
    assert silent.onboard_control_sensors_present & rc_bit
    assert silent.onboard_control_sensors_health & rc_bit == 0


def test_the_rangefinder_is_listed_healthy_while_heard_and_sent_as_distance_sensor():
    from mavlink_dialect import companion as d

    mav = new_encoder(1)
    bit = d.MAV_SYS_STATUS_SENSOR_LASER_POSITION
    sys_status, distance = (
        STREAMS[d.MAVLINK_MSG_ID_SYS_STATUS],
        STREAMS[d.MAVLINK_MSG_ID_DISTANCE_SENSOR],
    )
    assert (
        sys_status.build(mav, Snapshot(now_us=10_000_000)).onboard_control_sensors_present & bit
        == 0
    )
    assert distance.build(mav, Snapshot()) is None
    reading = RangeReading(
        t_us=9_990_000, distance_m=3.45, min_distance_m=0.1, max_distance_m=12.0,
        ground_clearance_m=0.1, signal_quality=80, valid=1,
    )  # fmt: skip
    snap = Snapshot(now_us=10_000_000, rangefinder=reading)
    heard = sys_status.build(mav, snap)
    assert heard.onboard_control_sensors_present & heard.onboard_control_sensors_health & bit
    msg = distance.build(mav, snap)
    assert (msg.current_distance, msg.min_distance, msg.max_distance) == (345, 10, 1200)
    assert msg.orientation == d.MAV_SENSOR_ROTATION_PITCH_270 and msg.signal_quality == 80
    reading.valid, reading.signal_quality = 0, 1  # high above the ground: still healthy
    assert sys_status.build(mav, snap).onboard_control_sensors_health & bit
    assert distance.build(mav, snap).current_distance == 1201
    snap.now_us = 10_600_000  # silent for 0.61 s
    assert sys_status.build(mav, snap).onboard_control_sensors_health & bit == 0
