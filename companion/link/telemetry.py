"""Telemetry streams: each a small named mapping from bus values to one MAVLink message.

The vehicle streams from boot (ground stations do not ask), at default rates that a
ground station changes per endpoint with MAV_CMD_SET_MESSAGE_INTERVAL.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from companion.link import flight_messages
from companion.link.codec import dialect as d
from companion.link.flight_messages import landed_state, mission_current, nav_controller_output
from companion.link.mode_messages import available_modes_monitor, current_mode
from companion.link.rate_messages import attitude_target, highres_imu
from companion.link.snapshot import SNAPSHOT_CHANNELS, Snapshot
from companion.link.system_messages import (
    battery_status,
    distance_sensor,
    sensor_bits,
    sys_status,
)
from companion.messages.navigation import NAV_ATTITUDE_VALID, NAV_POSITION_VALID, NAV_VELOCITY_VALID

__all__ = ["SNAPSHOT_CHANNELS", "STREAMS", "Snapshot", "sensor_bits"]


Builder = Callable[[Any, Snapshot], Any]


def _finite(x: float, fallback: float = 0.0) -> float:
    return x if math.isfinite(x) else fallback


def _int16(x: float) -> int:
    """Saturate to an int16 field (a sensor beyond its range must not break the link)."""
    return max(-32768, min(32767, round(_finite(x))))


def _deg360(rad: float) -> float:
    """An angle in degrees within [0, 360); 0 for values that are not finite."""
    return _finite(math.degrees(_finite(rad)) % 360.0) % 360.0


def _int32(x: float) -> int:
    return max(-(2**31), min(2**31 - 1, round(_finite(x))))


def _f32(x: float) -> float:
    """Keep a value inside float32 (NaN stays NaN: MAVLink's 'unknown')."""
    return x if math.isnan(x) else max(-3.0e38, min(3.0e38, x))


def _attitude(mav: Any, s: Snapshot) -> Any:
    n = s.nav
    if n is None or not n.flags & NAV_ATTITUDE_VALID:
        return None
    return mav.attitude_encode(
        s.time_boot_ms,
        _f32(n.roll_rad),
        _f32(n.pitch_rad),
        _f32(n.yaw_rad),
        _f32(_finite(n.roll_rate_rad_s)),
        _f32(_finite(n.pitch_rate_rad_s)),
        _f32(_finite(n.yaw_rate_rad_s)),
    )


def _attitude_quaternion(mav: Any, s: Snapshot) -> Any:
    n = s.nav
    if n is None or not n.flags & NAV_ATTITUDE_VALID:
        return None
    q = [_f32(v) for v in n.q]
    rates = tuple(
        _f32(_finite(r)) for r in (n.roll_rate_rad_s, n.pitch_rate_rad_s, n.yaw_rate_rad_s)
    )
    return mav.attitude_quaternion_encode(s.time_boot_ms, *q, *rates, [0.0] * 4)


def _global_position(mav: Any, s: Snapshot) -> Any:
    n = s.nav
    if n is None or not n.flags & NAV_POSITION_VALID:
        return None
    rel = n.alt_msl_m - s.home_alt_m if math.isfinite(s.home_alt_m) else 0.0
    heading = _deg360(n.yaw_rad)
    return mav.global_position_int_encode(
        s.time_boot_ms,
        _int32(n.lat_deg * 1e7),
        _int32(n.lon_deg * 1e7),
        _int32(n.alt_msl_m * 1000),
        _int32(rel * 1000),
        _int16(_finite(n.vn_m_s) * 100),
        _int16(_finite(n.ve_m_s) * 100),
        _int16(_finite(n.vd_m_s) * 100),
        round(heading * 100) % 36000,
    )


def _gps_raw(mav: Any, s: Snapshot) -> Any:
    g = s.gps
    if g is None:
        return mav.gps_raw_int_encode(
            s.time_boot_ms * 1000, d.GPS_FIX_TYPE_NO_GPS, 0, 0, 0, 65535, 65535, 65535, 65535, 255
        )

    def u16(v: float, scale: float) -> int:
        x = v * scale
        return 65535 if not math.isfinite(x) else max(0, min(65534, round(x)))

    cog = 65535 if not math.isfinite(g.course_rad) else round(_deg360(g.course_rad) * 100) % 36000
    return mav.gps_raw_int_encode(
        g.t_us,
        g.fix_type,
        _int32(g.lat_deg * 1e7),
        _int32(g.lon_deg * 1e7),
        _int32(_finite(g.alt_msl_m) * 1000),
        u16(g.hdop, 100),
        u16(g.vdop, 100),
        u16(g.ground_speed_m_s, 100),
        cog,
        g.satellites,
        h_acc=_mm(g.eph_m),  # what MAVSDK's RawGps reads as its uncertainty (0: not known)
        v_acc=_mm(g.epv_m),
    )


def _mm(metres: float) -> int:
    """An accuracy in whole millimetres for a uint32 field (0, MAVLink's "not known", when
    it is not a number), clamped as ``_int32`` clamps."""
    return max(0, min(2**32 - 1, round(_finite(metres * 1000.0))))


def _vfr_hud(mav: Any, s: Snapshot) -> Any:
    n = s.nav
    if n is None:
        return None
    ground = _f32(math.hypot(_finite(n.vn_m_s), _finite(n.ve_m_s)))
    heading = round(_deg360(n.yaw_rad)) % 360
    c = s.control  # while the flight controller runs: its airspeed estimate and throttle
    airspeed = _f32(c.airspeed_m_s) if c is not None and math.isfinite(c.airspeed_m_s) else ground
    throttle = round(100 * min(1.0, max(0.0, _finite(c.throttle)))) if c is not None else 0
    alt, climb = _f32(_finite(n.alt_msl_m)), _f32(-_finite(n.vd_m_s))
    return mav.vfr_hud_encode(airspeed, ground, heading, throttle, alt, climb)


def _system_time(mav: Any, s: Snapshot) -> Any:
    return mav.system_time_encode(s.unix_us, s.time_boot_ms)


def _servo_output(mav: Any, s: Snapshot) -> Any:
    if s.servos is None:
        return None
    return mav.servo_output_raw_encode(s.servos.t_us & 0xFFFFFFFF, 0, *list(s.servos.pulse_us))


def _scaled_imu(mav: Any, s: Snapshot) -> Any:
    i = s.imu
    if i is None:
        return None
    mg = lambda a: _int16(a / 9.80665 * 1000)  # noqa: E731
    mrad = lambda w: _int16(w * 1000)  # noqa: E731
    return mav.scaled_imu_encode(
        s.time_boot_ms,
        mg(i.ax_m_s2),
        mg(i.ay_m_s2),
        mg(i.az_m_s2),
        mrad(i.gx_rad_s),
        mrad(i.gy_rad_s),
        mrad(i.gz_rad_s),
        0,
        0,
        0,
    )


def _extended_sys_state(mav: Any, s: Snapshot) -> Any:
    landed = d.MAV_LANDED_STATE_UNDEFINED
    if (controlled := landed_state(s.control)) is not None:
        landed = controlled
    elif s.nav is not None and s.nav.flags & NAV_VELOCITY_VALID:
        moving = math.hypot(_finite(s.nav.vn_m_s), _finite(s.nav.ve_m_s)) > 5.0
        landed = d.MAV_LANDED_STATE_IN_AIR if moving else d.MAV_LANDED_STATE_ON_GROUND
    return mav.extended_sys_state_encode(d.MAV_VTOL_STATE_UNDEFINED, landed)


def _mission_current(mav: Any, s: Snapshot) -> Any:
    return mission_current(
        mav, s.mission_seq, s.mission_total, s.control, s.mission_completed, s.mission_paused
    )


def _home_position(mav: Any, s: Snapshot) -> Any:
    if s.home is None:
        return None
    lat, lon, alt = s.home
    q = [1.0, 0.0, 0.0, 0.0]
    return mav.home_position_encode(
        _int32(lat * 1e7), _int32(lon * 1e7), _int32(alt * 1000), 0, 0, 0, q, 0, 0, 0,
        s.time_boot_ms * 1000,  # time since boot, as PX4 stamps it
    )  # fmt: skip


def _u32(x: int) -> int:
    return max(0, min(2**32 - 1, int(x)))


def _plugin_health(mav: Any, s: Snapshot) -> Any:
    rows = s.health.rows() if s.health is not None else []
    if not rows:
        return None
    index = s.health_cursor % len(rows)
    s.health_cursor = index + 1
    r = rows[index]
    return mav.plugin_health_encode(
        s.time_boot_ms,
        _u32(r.pid),
        _u32(r.restarts),
        _u32(r.frames_ok),
        _u32(r.frames_bad),
        _u32(r.dropped),
        _f32(_finite(r.cpu_pct)),
        _f32(_finite(r.step_p99_us)),
        index,
        len(rows),
        r.state,
        r.name[:24],
    )


def _navigator_name(s: Snapshot) -> bytes:
    for row in s.health.rows() if s.health is not None else []:
        if row.kind.startswith(b"nav."):
            return row.kind[4:20]
    return b""


def _nav_status(mav: Any, s: Snapshot) -> Any:
    n = s.nav
    if n is None:
        return None
    std = [
        [_f32(_finite(v, math.nan)) for v in arr]
        for arr in (n.pos_std_m, n.vel_std_m_s, n.att_std_rad)
    ]
    return mav.nav_status_encode(
        s.time_boot_ms, n.flags, n.gps_rejected, n.heading_rejected, *std, 0.0, _navigator_name(s)
    )


@dataclass(frozen=True)
class Stream:
    name: str
    msg_id: int
    default_hz: float
    build: Builder


STREAMS: dict[int, Stream] = {
    s.msg_id: s
    for s in (
        Stream("ATTITUDE", d.MAVLINK_MSG_ID_ATTITUDE, 10.0, _attitude),
        # On by default, as PX4 streams it: QGroundControl 4.4.5 takes the attitude and
        # heading from it alone once one has come (Vehicle::_handleAttitude), so a stream
        # that its PID Tuning page turned on and then back to the default (off) froze them.
        Stream(
            "ATTITUDE_QUATERNION", d.MAVLINK_MSG_ID_ATTITUDE_QUATERNION, 10.0, _attitude_quaternion
        ),
        Stream("GLOBAL_POSITION_INT", d.MAVLINK_MSG_ID_GLOBAL_POSITION_INT, 5.0, _global_position),
        Stream("GPS_RAW_INT", d.MAVLINK_MSG_ID_GPS_RAW_INT, 2.0, _gps_raw),
        Stream("VFR_HUD", d.MAVLINK_MSG_ID_VFR_HUD, 4.0, _vfr_hud),
        Stream("SYS_STATUS", d.MAVLINK_MSG_ID_SYS_STATUS, 1.0, sys_status),
        Stream("BATTERY_STATUS", d.MAVLINK_MSG_ID_BATTERY_STATUS, 0.5, battery_status),
        Stream("DISTANCE_SENSOR", d.MAVLINK_MSG_ID_DISTANCE_SENSOR, 2.0, distance_sensor),
        Stream("SYSTEM_TIME", d.MAVLINK_MSG_ID_SYSTEM_TIME, 0.5, _system_time),
        Stream("SERVO_OUTPUT_RAW", d.MAVLINK_MSG_ID_SERVO_OUTPUT_RAW, 2.0, _servo_output),
        Stream("RC_CHANNELS", d.MAVLINK_MSG_ID_RC_CHANNELS, 2.0, flight_messages.rc_channels),
        Stream("SCALED_IMU", d.MAVLINK_MSG_ID_SCALED_IMU, 2.0, _scaled_imu),
        Stream("HIGHRES_IMU", d.MAVLINK_MSG_ID_HIGHRES_IMU, 0.0, highres_imu),
        Stream("ATTITUDE_TARGET", d.MAVLINK_MSG_ID_ATTITUDE_TARGET, 0.0, attitude_target),
        Stream("EXTENDED_SYS_STATE", d.MAVLINK_MSG_ID_EXTENDED_SYS_STATE, 1.0, _extended_sys_state),
        Stream("MISSION_CURRENT", d.MAVLINK_MSG_ID_MISSION_CURRENT, 1.0, _mission_current),
        Stream(
            "NAV_CONTROLLER_OUTPUT",
            d.MAVLINK_MSG_ID_NAV_CONTROLLER_OUTPUT,
            2.0,
            lambda m, s: nav_controller_output(m, s.control),
        ),
        Stream("HOME_POSITION", d.MAVLINK_MSG_ID_HOME_POSITION, 0.2, _home_position),
        Stream("PLUGIN_HEALTH", d.MAVLINK_MSG_ID_PLUGIN_HEALTH, 2.0, _plugin_health),
        Stream("NAV_STATUS", d.MAVLINK_MSG_ID_NAV_STATUS, 1.0, _nav_status),
        Stream(
            "CURRENT_MODE",
            d.MAVLINK_MSG_ID_CURRENT_MODE,
            0.5,
            lambda m, s: current_mode(m, s.status, s.assumed_mode, s.px4_modes),
        ),
        Stream(
            "AVAILABLE_MODES_MONITOR",
            d.MAVLINK_MSG_ID_AVAILABLE_MODES_MONITOR,
            0.2,
            lambda m, s: available_modes_monitor(m),
        ),
    )
}
