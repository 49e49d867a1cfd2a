"""The thesis's final navigator: attitude from the compass, position and velocity from GPS.

Position and velocity are smoothed by a constant-velocity Kalman filter in a
local north-east-down frame about the first fix, predicted with the REAL time between
fixes (the 2006 filter assumed exactly one second and blew up after outages). Without
fixes the filter coasts and its uncertainty grows; the solution says so in its flags.

The filter is written here with numpy alone: filterpy, which it used before, declares
scipy and matplotlib as dependencies (~180 MB an on-board install has no other use for).
Its equations are filterpy's ``KalmanFilter.predict``/``update`` (Joseph-form covariance)
with the measurement matrix the identity, in the same order, so the figures are the same.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from companion.messages import Compass, GpsFix, NavFlags, NavState
from companion.navigation.rotations import euler_to_quaternion

EARTH_RADIUS_M = 6_378_137.0


@dataclass(frozen=True)
class GpsCompassConfig:
    """Tuning: process noise and when inputs count as stale."""

    accel_noise_m_s2: float = 2.0  # white-noise acceleration of a small aeroplane
    default_pos_std_m: float = 3.0  # when the fix carries no accuracy
    vel_std_m_s: float = 0.3
    gps_timeout_s: float = 2.0
    compass_timeout_s: float = 1.0


class ConstantVelocityFilter:
    """Linear Kalman filter whose state (x, column vector) is measured directly (H = I)."""

    def __init__(self, dim: int) -> None:
        self.x = np.zeros((dim, 1))
        self.P = np.eye(dim)
        self._eye = np.eye(dim)

    def predict(self, f: np.ndarray, q: np.ndarray) -> None:
        """Move the state through ``f``, adding process noise ``q``."""
        self.x = f @ self.x
        self.P = f @ self.P @ f.T + q

    def update(self, z: np.ndarray, r: np.ndarray) -> None:
        """Fuse a measurement ``z`` of the whole state with noise covariance ``r``."""
        gain = self.P @ np.linalg.inv(self.P + r)
        self.x = self.x + gain @ (z - self.x)
        # Joseph form: stays symmetric and positive definite when the gain is rounded.
        keep = self._eye - gain
        self.P = keep @ self.P @ keep.T + gain @ r @ gain.T


class GpsCompassNavigator:
    """Feed samples in time order; ``state(t_us)`` gives the solution at that time."""

    def __init__(self, config: GpsCompassConfig | None = None) -> None:
        self.cfg = config or GpsCompassConfig()
        self.kf = ConstantVelocityFilter(6)
        self.ref: tuple[float, float, float] | None = None  # lat, lon, alt of the first fix
        self.t_kf_us: int | None = None
        self.last_fix_us: int | None = None
        self.compass: Compass | None = None
        self.fixes = 0
        self.rejected = 0

    def _transition(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        f = np.eye(6)
        f[0:3, 3:6] = np.eye(3) * dt
        q = self.cfg.accel_noise_m_s2**2
        block = np.array([[dt**4 / 4, dt**3 / 2], [dt**3 / 2, dt**2]]) * q
        big_q = np.zeros((6, 6))
        for axis in range(3):
            idx = [axis, axis + 3]
            big_q[np.ix_(idx, idx)] = block
        return f, big_q

    def _predict(self, t_us: int) -> None:
        if self.t_kf_us is None or t_us <= self.t_kf_us:
            return
        f, q = self._transition((t_us - self.t_kf_us) / 1e6)
        self.kf.predict(f, q)
        self.t_kf_us = t_us

    def _predicted(self, t_us: int) -> tuple[np.ndarray, np.ndarray]:
        """State and covariance at ``t_us`` without moving the filter (a later fix may
        still be stamped earlier than a query: GPS time stamps lag)."""
        dt = max(0.0, (t_us - (self.t_kf_us or t_us)) / 1e6)
        f, q = self._transition(dt)
        return f @ self.kf.x, f @ self.kf.P @ f.T + q

    @staticmethod
    def _to_ned(ref: tuple[float, float, float], lat: float, lon: float, alt: float) -> np.ndarray:
        lat0, lon0, alt0 = ref
        north = math.radians(lat - lat0) * EARTH_RADIUS_M
        east = math.radians(lon - lon0) * EARTH_RADIUS_M * math.cos(math.radians(lat0))
        return np.array([north, east, -(alt - alt0)])

    def on_gps(self, fix: GpsFix) -> None:
        """Fuse one GPS fix (2-D or better); anything less is ignored."""
        if fix.fix_type < 2 or not (math.isfinite(fix.lat_deg) and math.isfinite(fix.lon_deg)):
            self.rejected += 1
            return
        alt = fix.alt_msl_m if math.isfinite(fix.alt_msl_m) else 0.0
        if self.ref is None:
            self.ref = (fix.lat_deg, fix.lon_deg, alt)
        pos = self._to_ned(self.ref, fix.lat_deg, fix.lon_deg, alt)
        vel = np.array([fix.vn_m_s, fix.ve_m_s, fix.vd_m_s])
        z = np.concatenate([pos, np.nan_to_num(vel)])
        pos_std = fix.eph_m if math.isfinite(fix.eph_m) else self.cfg.default_pos_std_m
        r = np.diag([pos_std**2] * 2 + [(pos_std * 1.5) ** 2] + [self.cfg.vel_std_m_s**2] * 3)
        if not math.isfinite(fix.vd_m_s):
            r[5, 5] = 1e6  # no vertical velocity measured: let the filter infer it
        if self.t_kf_us is None:
            self.kf.x = z.reshape(6, 1)
            self.kf.P = r.copy()
            self.t_kf_us = fix.t_us
        else:
            self._predict(fix.t_us)
            self.kf.update(z.reshape(6, 1), r)
        self.last_fix_us = fix.t_us
        self.fixes += 1

    def on_compass(self, reading: Compass) -> None:
        """The compass gives the attitude directly."""
        self.compass = reading

    def state(self, t_us: int) -> NavState:
        """The solution at ``t_us`` (position and velocity predicted to that time)."""
        msg = NavState(t_us=t_us)
        flags = 0
        c = self.compass
        if c is not None and (t_us - c.t_us) / 1e6 < self.cfg.compass_timeout_s:
            yaw = math.remainder(c.heading_rad, 2 * math.pi)
            msg.roll_rad, msg.pitch_rad, msg.yaw_rad = c.roll_rad, c.pitch_rad, yaw
            msg.q[:] = euler_to_quaternion(c.roll_rad, c.pitch_rad, yaw)
            flags |= NavFlags.ATTITUDE_VALID | NavFlags.HEADING_VALID
        for field in ("roll_rate_rad_s", "pitch_rate_rad_s", "yaw_rate_rad_s"):
            setattr(msg, field, math.nan)
        if self.ref is not None and self.t_kf_us is not None:
            flags |= self._fill_position(msg, t_us, self.ref)
        msg.flags = int(flags)
        msg.gps_rejected = self.rejected
        return msg

    def _fill_position(self, msg: NavState, t_us: int, ref: tuple[float, float, float]) -> int:
        x_col, p = self._predicted(t_us)
        x = x_col.ravel()
        lat0, lon0, alt0 = ref
        msg.lat_deg = lat0 + math.degrees(x[0] / EARTH_RADIUS_M)
        msg.lon_deg = lon0 + math.degrees(x[1] / (EARTH_RADIUS_M * math.cos(math.radians(lat0))))
        msg.alt_msl_m = alt0 - x[2]
        msg.vn_m_s, msg.ve_m_s, msg.vd_m_s = x[3], x[4], x[5]
        std = np.sqrt(np.diag(p))
        msg.pos_std_m[:] = std[0:3].tolist()
        msg.vel_std_m_s[:] = std[3:6].tolist()
        flags = NavFlags.POSITION_VALID | NavFlags.VELOCITY_VALID | NavFlags.ALTITUDE_VALID
        stale = self.last_fix_us is None or (t_us - self.last_fix_us) / 1e6 > self.cfg.gps_timeout_s
        return int(flags | NavFlags.DEAD_RECKONING) if stale else int(flags)
