"""What a pilot commands: stick positions and the mode switch, from a receiver or a joystick."""

from __future__ import annotations

import ctypes
import enum

from companion.messages.base import Message

RC_MAX_CHANNELS = 18  # SBUS: 16 proportional channels and two digital ones


class PilotSource(enum.IntEnum):
    """Where the sticks came from."""

    RC = 1  # a radio receiver on a serial port (sensors.rc_input)
    MANUAL_CONTROL = 2  # MAVLink MANUAL_CONTROL: QGroundControl's joystick (link.mavlink)


class PilotFlags(enum.IntFlag):
    """Why these sticks may not be flown."""

    FAILSAFE = 1  # the receiver says its radio link is lost (it sends failsafe positions)
    FRAME_LOST = 2  # the receiver missed the transmitter's last frame
    THROTTLE_LOW = 4  # throttle channel below THR_FS_VALUE: a receiver's failsafe throttle


# As a plain int: an IntFlag operand sends every ``&`` through the enum machinery, and the
# controller asks at every step.
_NOT_A_PILOT = int(PilotFlags.FAILSAFE | PilotFlags.THROTTLE_LOW)


class PilotInput(Message):
    """Sticks in the stick convention of ``ActuatorCommand``: roll + right, pitch + nose up
    (stick pulled back), yaw + right, all in [-1, 1]; throttle in [0, 1].

    ``mode_switch`` is the flight-mode switch position 0..5 (FLTMODE1..6), -1 when there is
    none. ``channels_us`` are the receiver's channels as pulse widths (RC_CHANNELS), 0 when
    unused. Producers: sensors.rc_input (sensors/rc, and sensors/rc_switch when the switch
    moved), link.mavlink (link/manual_control). Consumers: vehicle.commander,
    control.fixed_wing, link.
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),  # when the receiver's frame (or the message) arrived
        ("roll", ctypes.c_double),
        ("pitch", ctypes.c_double),
        ("yaw", ctypes.c_double),
        ("throttle", ctypes.c_double),
        ("mode_switch", ctypes.c_int8),
        ("flags", ctypes.c_uint8),  # PilotFlags
        ("source", ctypes.c_uint8),  # PilotSource
        ("rssi", ctypes.c_uint8),  # 0-254, 255 unknown (RC_CHANNELS)
        ("channel_count", ctypes.c_uint8),
        ("channels_us", ctypes.c_uint16 * RC_MAX_CHANNELS),
    ]

    def usable(self) -> bool:
        """Whether the sticks are a pilot's (not a receiver's failsafe positions)."""
        return not self.flags & _NOT_A_PILOT
