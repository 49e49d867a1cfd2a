"""Normalised surface commands and the servo outputs written to the device."""

from __future__ import annotations

import ctypes

from companion.messages.base import Message


class ActuatorCommand(Message):
    """Normalised surface commands from control: surfaces in [-1, 1], throttle in [0, 1].

    Signs follow the stick: aileron + rolls right, elevator + pitches the nose up, rudder +
    yaws right. ``aux`` carries extra surfaces (flaps first) in [-1, 1]; NaN = not driven.
    Producers: control. Consumers: actuators.minissc.
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("aileron", ctypes.c_double),
        ("elevator", ctypes.c_double),
        ("rudder", ctypes.c_double),
        ("throttle", ctypes.c_double),
        ("aux", ctypes.c_double * 4),
        ("armed", ctypes.c_uint8),
    ]


class ServoOutput(Message):
    """What the servo card was told, per channel. Producers: actuators.*. Consumers: link."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("pulse_us", ctypes.c_uint16 * 8),  # equivalent PWM pulse width, 0 = channel unused
        ("position", ctypes.c_uint8 * 8),  # Mini SSC position 0-254
        # The t_us of the ActuatorCommand these positions answer (-1: none, e.g. safe on
        # stale input); written after the bytes, so a lockstep simulator can wait for it.
        ("command_t_us", ctypes.c_int64),
        # Bytes written to the card since the plug-in started, these included: a pty hands
        # them to the simulator a moment after the write returns, which waits for them all.
        ("bytes_out", ctypes.c_uint64),
    ]


class CameraCapture(Message):
    """A photo the camera's shutter was worked for, where and how the aircraft was then.

    The fields are PX4's ``camera_capture`` (names, units, types), not the registry's
    unit-suffixed names: the flight log records this channel as that topic, and
    QGroundControl's GeoTag Images reads exactly those fields from a ULog (its 4.4 parser
    finds each by name in the format, adding up the sizes of the fields before it).
    Producers: control. Consumers: link (CAMERA_TRIGGER), the flight log.
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),  # the navigation state's time the photo was taken at
        ("timestamp_utc", ctypes.c_uint64),  # the same instant in UTC, µs (0: no GPS time)
        ("lat", ctypes.c_double),  # degrees
        ("lon", ctypes.c_double),  # degrees
        ("alt", ctypes.c_float),  # m above mean sea level
        ("ground_distance", ctypes.c_float),  # m above home
        ("q", ctypes.c_float * 4),  # body → NED attitude, (w, x, y, z)
        ("seq", ctypes.c_uint32),  # the photo's number, from 1 each flight
        ("result", ctypes.c_int8),  # 1: the shutter was worked
    ]
