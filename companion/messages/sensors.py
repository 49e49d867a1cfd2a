"""What the device drivers publish: raw IMU, magnetometer, GPS, compass and barometer samples."""

from __future__ import annotations

import ctypes
import enum

from companion.messages.base import Message


class Imu(Message):
    """Specific force and angular rate, body FRD (level and still: az_m_s2 ≈ -9.81).

    Producers: sensors.serial_imu, sensors.replay. Consumers: nav.ins_ekf, link (SCALED_IMU).
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("ax_m_s2", ctypes.c_double),
        ("ay_m_s2", ctypes.c_double),
        ("az_m_s2", ctypes.c_double),
        ("gx_rad_s", ctypes.c_double),
        ("gy_rad_s", ctypes.c_double),
        ("gz_rad_s", ctypes.c_double),
        ("temp_c", ctypes.c_double),  # NaN when the device does not report it
    ]


class Magnetometer(Message):
    """Magnetic field, body FRD, in gauss.

    Producers: sensors.serial_imu, sensors.os3000 (when M fields present), sensors.replay.
    Consumers: nav.ins_ekf, link, sensors.os3000 (whether another magnetometer speaks).
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("mx_gauss", ctypes.c_double),
        ("my_gauss", ctypes.c_double),
        ("mz_gauss", ctypes.c_double),
    ]


class GpsFixType(enum.IntEnum):
    """Same numbering as MAVLink's GPS_FIX_TYPE."""

    NO_GPS = 0
    NO_FIX = 1
    FIX_2D = 2
    FIX_3D = 3
    DGPS = 4
    RTK_FLOAT = 5
    RTK_FIXED = 6


class GpsFix(Message):
    """One GPS epoch: position WGS-84, velocity NED, quality.

    Producers: sensors.nmea_gps, sensors.replay. Consumers: nav.*, link (GPS_RAW_INT).
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("utc_us", ctypes.c_int64),  # UTC of the fix, µs since 1970; 0 when unknown
        ("lat_deg", ctypes.c_double),
        ("lon_deg", ctypes.c_double),
        ("alt_msl_m", ctypes.c_double),
        ("vn_m_s", ctypes.c_double),
        ("ve_m_s", ctypes.c_double),
        ("vd_m_s", ctypes.c_double),  # NaN when no vertical velocity is known
        ("vd_std_m_s", ctypes.c_double),  # 1-σ of vd when the source says; 0 or NaN: unknown
        ("ground_speed_m_s", ctypes.c_double),
        ("course_rad", ctypes.c_double),  # over ground, [0, 2π) from north; NaN unknown
        ("hdop", ctypes.c_double),
        ("vdop", ctypes.c_double),
        ("eph_m", ctypes.c_double),  # horizontal 1-σ position error estimate
        ("epv_m", ctypes.c_double),
        ("fix_type", ctypes.c_uint8),  # GpsFixType
        ("satellites", ctypes.c_uint8),  # 255 when unknown
    ]


class Compass(Message):
    """Attitude as a tilt-compensated digital compass reports it (OS-3000 `$C`).

    Producers: sensors.os3000, sensors.replay. Consumers: nav.gps_compass, nav.ins_ekf.
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("heading_rad", ctypes.c_double),  # magnetic or true as configured, [0, 2π)
        ("pitch_rad", ctypes.c_double),
        ("roll_rad", ctypes.c_double),
        ("temp_c", ctypes.c_double),
    ]


class Baro(Message):
    """Barometric altitude relative to the first reading.

    Producers: sensors.serial_imu ($VNIMU pressure), sensors.replay. Consumers: nav.ins_ekf.
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("alt_rel_m", ctypes.c_double),
        ("pressure_pa", ctypes.c_double),  # NaN when unknown
    ]


class BatteryLevel(enum.IntEnum):
    """How much is left, as the battery plug-in judges it against its BATT_* thresholds."""

    OK = 0
    LOW = 1  # BATT_LOW_VOLT for BATT_LOW_TIMER, or BATT_LOW_MAH left
    CRITICAL = 2  # BATT_CRT_VOLT for BATT_LOW_TIMER, or BATT_CRT_MAH left


class Battery(Message):
    """The flight battery: measured voltage and current, and what the gauge makes of them.

    Producer: sensors.battery. Consumers: link (BATTERY_STATUS, SYS_STATUS), the commander
    (low-battery failsafe), logger.
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),  # when the monitor measured it
        ("voltage_v", ctypes.c_double),  # pack voltage, filtered over ~1 s of sensor time
        ("current_a", ctypes.c_double),  # drawn from the pack (positive discharging); NaN unknown
        ("consumed_mah", ctypes.c_double),  # integrated current since start; NaN unknown
        ("remaining", ctypes.c_double),  # 0..1 of BATT_CAPACITY (of the cells' voltage range
        # when the capacity is 0); NaN when neither is known
        ("level", ctypes.c_uint8),  # BatteryLevel
    ]


class RangeReading(Message):
    """A downward rangefinder's reading: distance along its beam to the ground.

    Producer: sensors.rangefinder. Consumers: control.fixed_wing (the landing's height
    above the runway), link (DISTANCE_SENSOR, SYS_STATUS), logger.
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),  # when the device measured it
        ("distance_m", ctypes.c_double),  # along the beam (body down); -1 when none
        ("min_distance_m", ctypes.c_double),  # the range it measures (RNGFND1_MIN/MAX)
        ("max_distance_m", ctypes.c_double),
        ("ground_clearance_m", ctypes.c_double),  # reading on the wheels (RNGFND1_GNDCLR)
        ("signal_quality", ctypes.c_uint8),  # MAVLink's: 0 unknown, 1 invalid, 2-100 %
        ("valid", ctypes.c_uint8),  # 1: in range with enough signal
    ]
