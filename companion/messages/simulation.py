"""The simulator's clock (the vehicle's time base in SITL) and its true state, for tools."""

from __future__ import annotations

import ctypes

from companion.messages.base import Message


class SimTruth(Message):
    """The simulator's true state, for scoring and the live status line.

    Producer: the simulator bridge. Consumers: tools and tests, never the flight code.
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("roll_rad", ctypes.c_double),
        ("pitch_rad", ctypes.c_double),
        ("yaw_rad", ctypes.c_double),  # [-π, π] from true north
        ("lat_deg", ctypes.c_double),
        ("lon_deg", ctypes.c_double),
        ("alt_msl_m", ctypes.c_double),
        ("alt_agl_m", ctypes.c_double),
        ("vn_m_s", ctypes.c_double),
        ("ve_m_s", ctypes.c_double),
        ("vd_m_s", ctypes.c_double),
        ("airspeed_m_s", ctypes.c_double),
    ]


class SimClock(Message):
    """Simulation time. Producer: the simulator bridge. Consumers: every vehicle clock."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("frame", ctypes.c_uint64),
    ]
