"""SYS_STATUS, BATTERY_STATUS and DISTANCE_SENSOR: which sensors the vehicle has, whether
each is healthy, its battery and its rangefinder, as QGroundControl shows them.

A sensor is present (and enabled) once it has published since boot, and healthy while its
newest sample is recent by the samples' own time stamps against the vehicle clock (never
by how fast the link ran): a device that falls silent turns red within its staleness
limit, on a busy machine as on an idle one.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from companion.link.codec import dialect as d
from companion.messages import BatteryLevel
from companion.messages.navigation import NAV_ATTITUDE_VALID, NAV_POSITION_VALID

if TYPE_CHECKING:
    from companion.link.snapshot import Snapshot

# Sample age beyond which a sensor is reported unhealthy (vehicle-clock microseconds).
STALE_US = {"imu": 500_000, "mag": 1_000_000, "baro": 1_000_000, "gps": 2_000_000}
# A receiver sends a frame every 7-20 ms; silence this long is a lost radio (PX4's
# COM_RC_LOSS_T is 0.5 s, ArduPlane's short failsafe 1.5 s). The failsafe action waits
# for FS_LONG_TIMEOUT; the sensor list says at once that the radio is gone.
RC_STALE_US = 1_000_000
BATTERY_STALE_US = 2_000_000
# A TFmini sends 100 frames a second. Out of range (high above the ground) is healthy:
# only a silent device is not.
RANGE_STALE_US = 500_000
UNKNOWN_CELL_MV = 65535
CHARGE_STATE = {
    BatteryLevel.OK: d.MAV_BATTERY_CHARGE_STATE_OK,
    BatteryLevel.LOW: d.MAV_BATTERY_CHARGE_STATE_LOW,
    BatteryLevel.CRITICAL: d.MAV_BATTERY_CHARGE_STATE_CRITICAL,
}


def fresh(sample: Any, now_us: int, limit_us: int) -> bool:
    """Whether a bus sample's ``t_us`` lies within ``limit_us`` of ``now_us``."""
    return sample is not None and now_us - sample.t_us <= limit_us


def _newest(*samples: Any) -> Any:
    present = [s for s in samples if s is not None]
    return max(present, key=lambda s: s.t_us) if present else None


def sensor_bits(s: Snapshot) -> tuple[int, int]:
    """SYS_STATUS present and healthy bits, true to what the bus shows."""
    present = healthy = 0
    mag = _newest(s.mag, s.compass)  # the OS-3000 is the magnetometer when no IMU has one
    for sample, bits, limit in (
        (s.imu, d.MAV_SYS_STATUS_SENSOR_3D_ACCEL | d.MAV_SYS_STATUS_SENSOR_3D_GYRO, "imu"),
        (mag, d.MAV_SYS_STATUS_SENSOR_3D_MAG, "mag"),
        (s.baro, d.MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE, "baro"),
        (s.gps, d.MAV_SYS_STATUS_SENSOR_GPS, "gps"),
    ):
        if sample is None:
            continue
        present |= bits
        usable = limit != "gps" or sample.fix_type >= 3
        if usable and fresh(sample, s.now_us, STALE_US[limit]):
            healthy |= bits
    if s.rc is not None:  # a receiver has been heard (the joystick is not a sensor)
        present |= d.MAV_SYS_STATUS_SENSOR_RC_RECEIVER
        if fresh(s.rc, s.now_us, RC_STALE_US) and s.rc.usable():
            healthy |= d.MAV_SYS_STATUS_SENSOR_RC_RECEIVER
    if s.battery is not None:
        present |= d.MAV_SYS_STATUS_SENSOR_BATTERY
        if fresh(s.battery, s.now_us, BATTERY_STALE_US) and s.battery.level == BatteryLevel.OK:
            healthy |= d.MAV_SYS_STATUS_SENSOR_BATTERY
    if s.rangefinder is not None:
        present |= d.MAV_SYS_STATUS_SENSOR_LASER_POSITION
        if fresh(s.rangefinder, s.now_us, RANGE_STALE_US):
            healthy |= d.MAV_SYS_STATUS_SENSOR_LASER_POSITION
    if s.nav is not None:
        present |= d.MAV_SYS_STATUS_AHRS
        if s.nav.flags & NAV_ATTITUDE_VALID:
            healthy |= d.MAV_SYS_STATUS_AHRS
    if s.prearm_ok is not None:  # as ArduPilot: QGroundControl shows "Ready To Fly" on it
        present |= d.MAV_SYS_STATUS_PREARM_CHECK
        if s.prearm_ok:
            healthy |= d.MAV_SYS_STATUS_PREARM_CHECK
    return present, healthy


def _scaled(value: float, scale: float, low: int, high: int, unknown: int) -> int:
    """``value * scale`` rounded into [low, high]; ``unknown`` when not a finite number."""
    x = value * scale
    return unknown if not math.isfinite(x) else round(min(high, max(low, x)))


def _battery_fields(s: Snapshot) -> tuple[int, int, int]:
    """SYS_STATUS's voltage (mV), current (cA) and remaining (%), each 'unknown' if so."""
    b = s.battery
    if b is None or not fresh(b, s.now_us, BATTERY_STALE_US):
        return UNKNOWN_CELL_MV, -1, -1
    volts = _scaled(b.voltage_v, 1000, 0, UNKNOWN_CELL_MV - 1, UNKNOWN_CELL_MV)
    amps = _scaled(b.current_a, 100, -1, 32767, -1)
    left = _scaled(b.remaining, 100, 0, 100, -1)
    return volts, amps, left


def geofence_bits(s: Snapshot) -> tuple[int, int, int]:
    """MAV_SYS_STATUS_GEOFENCE as ArduPilot sets it: present with a fence stored, enabled
    with FENCE_ENABLE on, healthy unless an enabled fence is breached (MAVProxy says "fence
    breach" whenever the healthy bit drops; it had at every connect, the bits all 0)."""
    bit = d.MAV_SYS_STATUS_GEOFENCE
    present = bit if s.fence is not None else 0
    enabled = bit if present and s.fence_enabled else 0
    breached, nav = False, s.nav
    if enabled and nav is not None and nav.flags & NAV_POSITION_VALID and s.fence is not None:
        breached = s.fence.breach(nav.lat_deg, nav.lon_deg) is not None
    return present, enabled, 0 if breached else bit


def sys_status(mav: Any, s: Snapshot) -> Any:
    present, healthy = sensor_bits(s)
    fence_present, fence_enabled, fence_healthy = geofence_bits(s)
    enabled = present | fence_enabled
    present, healthy = present | fence_present, healthy | fence_healthy
    load = 0
    if s.health is not None:
        load = min(1000, round(sum(r.cpu_pct for r in s.health.rows()) * 10 / 2))
    volts, amps, left = _battery_fields(s)
    return mav.sys_status_encode(
        present, enabled, healthy, load, volts, amps, left, 0, 0, 0, 0, 0, 0
    )


def battery_status(mav: Any, s: Snapshot) -> Any:
    """The pack as one battery (id 0): total voltage in cell 0, others unknown."""
    b = s.battery
    if b is None:
        return None
    volts, amps, left = _battery_fields(s)
    cells = [volts] + [UNKNOWN_CELL_MV] * 9
    used = (
        -1 if not math.isfinite(b.consumed_mah) else min(2**31 - 1, max(0, round(b.consumed_mah)))
    )
    state = CHARGE_STATE.get(b.level, d.MAV_BATTERY_CHARGE_STATE_UNDEFINED)
    if volts == UNKNOWN_CELL_MV:  # silent: QGroundControl must not show stale figures as news
        state = d.MAV_BATTERY_CHARGE_STATE_UNHEALTHY
    return mav.battery_status_encode(
        0,
        d.MAV_BATTERY_FUNCTION_ALL,
        d.MAV_BATTERY_TYPE_LIPO,
        32767,  # INT16_MAX: temperature unknown
        cells,
        amps,
        used,
        -1,  # energy consumed: unknown
        left,
        0,  # time remaining: not provided
        state,
    )


def distance_sensor(mav: Any, s: Snapshot) -> Any:
    """The downward lidar (id 0, pointing down); out of range reads one past its maximum,
    with signal quality 1 (invalid), as MAVLink asks. None without a rangefinder."""
    r = s.rangefinder
    if r is None:
        return None
    low = _scaled(r.min_distance_m, 100, 0, 65534, 0)
    high = _scaled(r.max_distance_m, 100, 0, 65534, 0)
    now = _scaled(r.distance_m, 100, 0, 65535, high + 1) if r.valid else high + 1
    return mav.distance_sensor_encode(
        s.time_boot_ms,
        low,
        high,
        now,
        d.MAV_DISTANCE_SENSOR_LASER,
        0,
        d.MAV_SENSOR_ROTATION_PITCH_270,
        255,  # covariance unknown
        signal_quality=r.signal_quality,
    )
