"""What the link reports to the vehicle: ground stations heard, messages for the operator."""

from __future__ import annotations

import ctypes

from companion.messages.base import Message


class LinkStatus(Message):
    """What the link hears from ground stations. Producer: link. Consumer: vehicle.commander."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        # Wall-clock seconds since the last ground-station heartbeat (NaN: none heard yet).
        # Wall time, not vehicle time: in a lockstep simulation a person's ground station
        # still beats once a real second.
        ("gcs_silence_s", ctypes.c_double),
    ]


class StatusText(Message):
    """A line for the ground station's message list (STATUSTEXT). Producers: any plug-in."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("severity", ctypes.c_uint8),  # MAV_SEVERITY
        ("text", ctypes.c_char * 200),  # sent on MAVLink in 50-byte chunks when longer
    ]
