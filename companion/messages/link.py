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


class MissionChanged(Message):
    """The stored mission, fence and rally points changed (or the link started).

    Producer: link (after a complete, valid upload or a clear). Consumers: vehicle.commander,
    control.fixed_wing, which reload the store when a checksum differs from theirs.
    ``mission_type``, ``count`` and ``checksum`` describe the change; ``counts`` and
    ``checksums`` every type (index = MAV_MISSION_TYPE), so a reader that only sees the
    newest value misses none. The checksum is the CRC-32 of the stored list.
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("mission_type", ctypes.c_uint8),
        ("count", ctypes.c_uint32),
        ("checksum", ctypes.c_uint32),
        ("counts", ctypes.c_uint32 * 3),
        ("checksums", ctypes.c_uint32 * 3),
    ]


class StatusText(Message):
    """A line for the ground station's message list (STATUSTEXT). Producers: any plug-in."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("severity", ctypes.c_uint8),  # MAV_SEVERITY
        ("text", ctypes.c_char * 200),  # sent on MAVLink in 50-byte chunks when longer
    ]

    @classmethod
    def of(cls, t_us: int, severity: int, text: str) -> StatusText:
        """The line ``text``, cut to what the field holds (with its terminating NUL)."""
        msg = cls(t_us=t_us, severity=severity)
        msg.text = text.encode()[:199]
        return msg


RTCM_MAX_BYTES = 4 * 180  # GPS_RTCM_DATA: at most four fragments of 180 bytes


class GpsInject(Message):
    """One whole RTCM message from the ground station (GPS_RTCM_DATA, its fragments joined),
    for the GPS receiver's port. Producer: the link; consumer: the GPS driver."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("length", ctypes.c_uint16),
        ("data", ctypes.c_uint8 * RTCM_MAX_BYTES),
    ]

    @classmethod
    def of(cls, t_us: int, data: bytes) -> GpsInject:
        """``data`` (at most RTCM_MAX_BYTES) as one message."""
        msg = cls(t_us=t_us, length=len(data))
        ctypes.memmove(msg.data, data, len(data))
        return msg

    def payload(self) -> bytes:
        """The message's bytes."""
        return bytes(self.data[: min(self.length, RTCM_MAX_BYTES)])
