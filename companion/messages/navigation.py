"""The navigation solution the navigators publish on nav/state."""

from __future__ import annotations

import ctypes
import enum

from companion.messages.base import Message


class NavFlags(enum.IntFlag):
    """Health bits of a navigation solution."""

    ATTITUDE_VALID = 1
    HEADING_VALID = 2
    VELOCITY_VALID = 4
    POSITION_VALID = 8
    ALTITUDE_VALID = 16
    DEAD_RECKONING = 32  # no GPS aiding: position is propagated only
    ALIGNING = 64
    GPS_REJECTED = 128  # the last GPS update failed its innovation gate
    HEADING_REJECTED = 256


# The same bits as plain ints, for the tests made at every step: ``flags & NavFlags.X``
# builds an enum value through enum.py's Python code (about 1.5 µs a test).
NAV_ATTITUDE_VALID = int(NavFlags.ATTITUDE_VALID)
NAV_VELOCITY_VALID = int(NavFlags.VELOCITY_VALID)
NAV_POSITION_VALID = int(NavFlags.POSITION_VALID)
NAV_DEAD_RECKONING = int(NavFlags.DEAD_RECKONING)
NAV_ALIGNING = int(NavFlags.ALIGNING)
NAV_GPS_REJECTED = int(NavFlags.GPS_REJECTED)
NAV_HEADING_REJECTED = int(NavFlags.HEADING_REJECTED)


class NavState(Message):
    """The navigation solution. Producers: nav.gps_compass or nav.ins_ekf (one of them).

    Consumers: control, link (ATTITUDE, GLOBAL_POSITION_INT, ...).
    Also used for ``sim/truth`` (the simulator's true state).
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("q", ctypes.c_double * 4),  # body→NED rotation, (w, x, y, z)
        ("roll_rad", ctypes.c_double),
        ("pitch_rad", ctypes.c_double),
        ("yaw_rad", ctypes.c_double),  # [-π, π] from true north
        ("roll_rate_rad_s", ctypes.c_double),
        ("pitch_rate_rad_s", ctypes.c_double),
        ("yaw_rate_rad_s", ctypes.c_double),
        ("lat_deg", ctypes.c_double),
        ("lon_deg", ctypes.c_double),
        ("alt_msl_m", ctypes.c_double),
        ("vn_m_s", ctypes.c_double),
        ("ve_m_s", ctypes.c_double),
        ("vd_m_s", ctypes.c_double),
        ("pos_std_m", ctypes.c_double * 3),  # 1-σ N, E, D
        ("vel_std_m_s", ctypes.c_double * 3),
        ("att_std_rad", ctypes.c_double * 3),  # 1-σ roll, pitch, yaw
        ("gyro_bias_rad_s", ctypes.c_double * 3),
        ("accel_bias_m_s2", ctypes.c_double * 3),
        ("flags", ctypes.c_uint32),  # NavFlags
        ("gps_rejected", ctypes.c_uint32),  # innovation-gate rejections since start
        ("heading_rejected", ctypes.c_uint32),
    ]
