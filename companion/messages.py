"""Every bus message type and the CHANNELS table: the one registry of the vehicle's data.

Each payload is a fixed-size ctypes structure, so it can live in iceoryx2 shared memory.
Field names carry their units; ``t_us`` (first field of every type) is the time the data
was measured in the vehicle time base (monotonic µs on hardware, simulation µs in SITL).
"Not set" for a float is NaN. Frames: body is FRD, navigation is local NED.
"""

from __future__ import annotations

import ctypes
import enum
import math
from dataclasses import dataclass
from typing import Literal

NAN = math.nan
MAX_PLUGINS = 32
NAME_LEN = 24


class Message(ctypes.Structure):
    """Base of every bus payload; subclasses declare ``_fields_`` starting with ``t_us``."""

    def as_dict(self) -> dict[str, object]:
        """Plain-Python view of the fields (arrays become lists, names become str)."""
        out: dict[str, object] = {}
        for field_name, _field_type, *_ in self._fields_:
            value = getattr(self, field_name)
            if isinstance(value, bytes):
                value = value.decode(errors="replace")
            elif isinstance(value, ctypes.Array):
                value = [v.as_dict() if isinstance(v, Message) else v for v in value]
            elif isinstance(value, Message):
                value = value.as_dict()
            out[field_name] = value
        return out


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
    Consumers: nav.ins_ekf, link.
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
    ]


class CommandId(enum.IntEnum):
    """Vehicle commands carried on ``link/commands``.

    START/STOP are the thesis's uplink commands; the others mirror the MAVLink commands
    that other plug-ins must act on.
    """

    START = 1  # start the flight group (arm)
    STOP = 2  # stop the flight group, servos safe (disarm)
    SET_MODE = 3  # param1 = FlightMode
    MISSION_START = 4  # param1 = first item, param2 = last item
    RETURN_TO_LAUNCH = 5
    REPOSITION = 6  # param1 = lat_deg, param2 = lon_deg, param3 = alt_msl_m
    RESTART_PLUGINS = 7  # restart every plug-in (MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN)
    LOITER = 8  # param1..3 = lat_deg, lon_deg, alt_msl_m (NaN: where it is)
    SET_HOME = 9  # param1 = 1: here; else param5..7 = lat_deg, lon_deg, alt_msl_m
    INJECT_FAILURE = 10  # param1..3 = MAVLink FAILURE_UNIT, FAILURE_TYPE, instance (simulator)


class CommandResult(enum.IntEnum):
    """Same numbering as MAVLink's MAV_RESULT."""

    ACCEPTED = 0
    TEMPORARILY_REJECTED = 1
    DENIED = 2
    UNSUPPORTED = 3
    FAILED = 4
    IN_PROGRESS = 5


class VehicleCommand(Message):
    """A command for the vehicle. Producers: link, tools. Consumers: exec_control, control."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("seq", ctypes.c_uint32),  # chosen by the sender; echoed in the CommandAck
        ("command", ctypes.c_uint16),  # CommandId
        ("source_sysid", ctypes.c_uint8),
        ("source_compid", ctypes.c_uint8),
        ("param", ctypes.c_double * 7),
    ]


class CommandAck(Message):
    """Outcome of a VehicleCommand. Producers: exec_control, commander, the simulator bridge.
    Consumers: link."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("seq", ctypes.c_uint32),
        ("command", ctypes.c_uint16),
        ("result", ctypes.c_uint8),  # CommandResult
        ("source", ctypes.c_char * NAME_LEN),  # who answered
        ("reason", ctypes.c_char * 48),  # why it was refused (told to the ground station)
    ]


class PluginState(enum.IntEnum):
    """Life-cycle state of a plug-in as the execution control sees it."""

    STOPPED = 0
    STARTING = 1
    RUNNING = 2
    BACKOFF = 3  # died; waiting before the next restart
    FAILED = 4  # gave up (too many restarts in a row)


class PluginStats(Message):
    """A plug-in's own counters, published about once a second by its runner.

    Producers: every plug-in process. Consumers: exec_control (merged into system/health).
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("name", ctypes.c_char * NAME_LEN),
        ("pid", ctypes.c_int32),
        ("steps", ctypes.c_uint64),
        ("frames_ok", ctypes.c_uint64),
        ("frames_bad", ctypes.c_uint64),  # checksum failures and garbage
        ("dropped", ctypes.c_uint64),  # samples lost on queue overflow
        ("step_p50_us", ctypes.c_double),
        ("step_p99_us", ctypes.c_double),
    ]


class PluginHealth(Message):
    """One row of the health table."""

    _fields_ = [
        ("name", ctypes.c_char * NAME_LEN),
        ("kind", ctypes.c_char * 48),  # the plug-in named in the config
        ("group", ctypes.c_char * 8),  # "core" or "flight"
        ("state", ctypes.c_uint8),  # PluginState
        ("pid", ctypes.c_int32),
        ("restarts", ctypes.c_uint32),
        ("cpu_pct", ctypes.c_double),  # share of one core over the last second
        ("rss_kib", ctypes.c_uint32),
        ("frames_ok", ctypes.c_uint64),
        ("frames_bad", ctypes.c_uint64),
        ("dropped", ctypes.c_uint64),
        ("step_p50_us", ctypes.c_double),
        ("step_p99_us", ctypes.c_double),
    ]


class SystemHealth(Message):
    """The execution control's table of every plug-in. Producer: exec_control.

    Consumers: `companion status`, link (plug-in health, SYS_STATUS).
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("supervisor_pid", ctypes.c_int32),
        ("flight_running", ctypes.c_uint8),  # the flight group is started (armed)
        ("count", ctypes.c_uint8),
        ("plugins", PluginHealth * MAX_PLUGINS),
    ]

    def rows(self) -> list[PluginHealth]:
        """The filled rows of the table."""
        return [self.plugins[i] for i in range(self.count)]


class FlightMode(enum.IntEnum):
    """The vehicle's flight modes (``companion.control.modes`` maps them to MAVLink's encodings)."""

    MANUAL = 1  # surfaces follow the pilot (no RC here: held neutral)
    STABILIZED = 2  # wings level, height held
    MISSION = 3  # fly the stored mission
    LOITER = 4  # circle where it is
    RTL = 5  # fly home and circle there
    GUIDED = 6  # fly to a commanded point and circle there
    TAKEOFF = 7


class VehicleStatus(Message):
    """Mode, home and the guided target. Producer: vehicle.commander. Consumers: link, control."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("mode", ctypes.c_uint8),  # FlightMode
        ("armed", ctypes.c_uint8),
        ("home_valid", ctypes.c_uint8),
        ("home_lat_deg", ctypes.c_double),
        ("home_lon_deg", ctypes.c_double),
        ("home_alt_msl_m", ctypes.c_double),
        ("target_lat_deg", ctypes.c_double),  # GUIDED: where to go (NaN otherwise)
        ("target_lon_deg", ctypes.c_double),
        ("target_alt_msl_m", ctypes.c_double),
        ("mission_first", ctypes.c_int32),  # MISSION: the item to start from
        ("changes", ctypes.c_uint32),  # mode changes since start
    ]


class MissionState(enum.IntEnum):
    """How far the running mission is (MAVLink's MISSION_STATE numbering)."""

    NOT_STARTED = 2
    ACTIVE = 3
    COMPLETE = 5


class ControlStatus(Message):
    """What the flight controller is doing. Producer: control.fixed_wing. Consumer: link.

    Feeds NAV_CONTROLLER_OUTPUT, MISSION_CURRENT and MISSION_ITEM_REACHED (sent when
    ``reached_count`` grows).
    """

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("nav_roll_rad", ctypes.c_double),
        ("nav_pitch_rad", ctypes.c_double),
        ("target_bearing_rad", ctypes.c_double),
        ("wp_dist_m", ctypes.c_double),
        ("alt_error_m", ctypes.c_double),
        ("aspd_error_m_s", ctypes.c_double),
        ("xtrack_error_m", ctypes.c_double),
        ("airspeed_m_s", ctypes.c_double),  # estimated (no airspeed sensor): GPS and wind
        ("wind_n_m_s", ctypes.c_double),
        ("wind_e_m_s", ctypes.c_double),
        ("mission_seq", ctypes.c_int32),
        ("mission_state", ctypes.c_uint8),  # MissionState
        ("landed", ctypes.c_uint8),
        ("reached_count", ctypes.c_uint32),
        ("last_reached", ctypes.c_int32),
    ]

    STALE_US = 2_000_000  # no newer status for this long: the controller has stopped

    def fresh(self, now_us: int) -> bool:
        """Whether the controller is still running (it publishes ten times a second)."""
        return now_us - self.t_us < self.STALE_US


class ParamChange(Message):
    """A parameter a ground station set. Producer: link. Consumers: the parameter's owner."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("value", ctypes.c_double),
        ("name", ctypes.c_char * 17),
    ]


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
        ("text", ctypes.c_char * 51),
    ]


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


@dataclass(frozen=True)
class Channel:
    """A named bus channel: its payload type and pattern (and depth for queues)."""

    name: str
    type: type[Message]
    pattern: Literal["queue", "latest"]
    depth: int = 1
    doc: str = ""
    many_producers: bool = False  # every plug-in may publish (e.g. system/plugin_stats)


def _channels(*chans: Channel) -> dict[str, Channel]:
    return {c.name: c for c in chans}


CHANNELS: dict[str, Channel] = _channels(
    Channel("sensors/imu", Imu, "queue", 64, "raw IMU samples"),
    Channel("sensors/mag", Magnetometer, "queue", 32, "raw magnetometer samples"),
    Channel("sensors/gps", GpsFix, "queue", 8, "GPS fixes"),
    Channel("sensors/compass", Compass, "queue", 32, "digital compass attitude"),
    Channel("sensors/baro", Baro, "queue", 32, "barometric altitude"),
    Channel("nav/state", NavState, "latest", doc="navigation solution"),
    Channel("sim/truth", SimTruth, "latest", doc="simulator's true state"),
    Channel("sim/clock", SimClock, "latest", doc="simulation time"),
    Channel("vehicle/status", VehicleStatus, "latest", doc="mode, home, guided target"),
    Channel("control/actuators", ActuatorCommand, "queue", 8, "normalised surfaces"),
    Channel("control/status", ControlStatus, "latest", doc="guidance and mission progress"),
    Channel("actuators/servos", ServoOutput, "latest", doc="servo outputs written"),
    Channel("link/commands", VehicleCommand, "queue", 16, "commands for the vehicle", True),
    Channel("link/command_acks", CommandAck, "queue", 16, "command outcomes"),
    Channel("system/plugin_stats", PluginStats, "queue", 64, "per-plug-in counters", True),
    Channel("system/health", SystemHealth, "latest", doc="the health table"),
    Channel("params/changes", ParamChange, "queue", 32, "parameters set from the ground"),
    Channel("link/status", LinkStatus, "latest", doc="ground-station heartbeats heard"),
    Channel("vehicle/statustext", StatusText, "queue", 16, "messages for the operator", True),
)


def channel(name: str) -> Channel:
    """The registered channel of that name; KeyError names the unknown channel."""
    try:
        return CHANNELS[name]
    except KeyError:
        raise KeyError(f"unknown bus channel {name!r}; known: {sorted(CHANNELS)}") from None
