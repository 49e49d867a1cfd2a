"""Streams off by default that ground stations turn on with SET_MESSAGE_INTERVAL.

ATTITUDE_TARGET: QGroundControl's PX4 PID Tuning pages for a plane (Rate and Attitude)
ask for it at 100 Hz beside ATTITUDE_QUATERNION (src/Vehicle/MAVLinkStreamConfig.cc,
``setHighRateRateAndAttitude``), and for the default rate (0) again on leaving; without it
both requests were answered "command not supported". It carries the attitude the flight
controller asks for (its roll and pitch demands at the present heading: a fixed wing's
controller demands no yaw) and its throttle; the body rates are marked as not given.

HIGHRES_IMU: MAVSDK's ``set_rate_imu`` (its highres_imu example asks 200 Hz): the IMU's
newest sample, the magnetometer and the barometer's pressure.
"""

from __future__ import annotations

import math
from typing import Any

from companion.link.codec import dialect as d

_RATES_NOT_GIVEN = (
    d.ATTITUDE_TARGET_TYPEMASK_BODY_ROLL_RATE_IGNORE
    | d.ATTITUDE_TARGET_TYPEMASK_BODY_PITCH_RATE_IGNORE
    | d.ATTITUDE_TARGET_TYPEMASK_BODY_YAW_RATE_IGNORE
)
_IMU_FIELDS = (
    d.HIGHRES_IMU_UPDATED_XACC | d.HIGHRES_IMU_UPDATED_YACC | d.HIGHRES_IMU_UPDATED_ZACC
    | d.HIGHRES_IMU_UPDATED_XGYRO | d.HIGHRES_IMU_UPDATED_YGYRO | d.HIGHRES_IMU_UPDATED_ZGYRO
)  # fmt: skip
_MAG_FIELDS = d.HIGHRES_IMU_UPDATED_XMAG | d.HIGHRES_IMU_UPDATED_YMAG | d.HIGHRES_IMU_UPDATED_ZMAG


def _quaternion(roll: float, pitch: float, yaw: float) -> list[float]:
    """w, x, y, z of a ZYX (yaw, pitch, roll) rotation, as MAVLink's attitude messages."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return [
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ]


def _finite(x: float) -> float:
    """A float32 field's value: 0 when unknown, saturated when beyond float32 (a sensor
    out of its range must not break the link)."""
    return max(-3.0e38, min(3.0e38, x)) if math.isfinite(x) else 0.0


def attitude_target(mav: Any, s: Any) -> Any:
    """The controller's attitude demand (None while it is not running)."""
    c, n = s.control, s.nav
    if c is None or n is None:
        return None
    q = _quaternion(_finite(c.nav_roll_rad), _finite(c.nav_pitch_rad), _finite(n.yaw_rad))
    thrust = min(1.0, max(0.0, _finite(c.throttle)))
    return mav.attitude_target_encode(s.time_boot_ms, _RATES_NOT_GIVEN, q, 0.0, 0.0, 0.0, thrust)


def highres_imu(mav: Any, s: Any) -> Any:
    """The newest IMU sample in SI units (None before the first)."""
    i = s.imu
    if i is None:
        return None
    fields, mag = _IMU_FIELDS, (0.0, 0.0, 0.0)
    if s.mag is not None:
        fields |= _MAG_FIELDS
        mag = (_finite(s.mag.mx_gauss), _finite(s.mag.my_gauss), _finite(s.mag.mz_gauss))
    pressure = 0.0
    if s.baro is not None and math.isfinite(s.baro.pressure_pa):
        fields |= d.HIGHRES_IMU_UPDATED_ABS_PRESSURE
        pressure = _finite(s.baro.pressure_pa / 100.0)  # hPa
    temperature = 0.0
    if math.isfinite(i.temp_c):
        fields |= d.HIGHRES_IMU_UPDATED_TEMPERATURE
        temperature = _finite(i.temp_c)
    accel = (_finite(i.ax_m_s2), _finite(i.ay_m_s2), _finite(i.az_m_s2))
    gyro = (_finite(i.gx_rad_s), _finite(i.gy_rad_s), _finite(i.gz_rad_s))
    return mav.highres_imu_encode(
        max(0, int(i.t_us)), *accel, *gyro, *mag, pressure, 0.0, 0.0, temperature, fields
    )
