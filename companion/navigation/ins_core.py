"""The INS's state, its propagation by the IMU and the Kalman update (``ins_ekf`` uses it).

Nominal state: position and velocity in a local NED frame, attitude as a body→NED
quaternion, accelerometer and gyro biases. Error state δx = [δp, δv, δθ (body), δb_a, δb_g].
"""

from __future__ import annotations

import math

import numpy as np

from companion.messages import NavFlags, NavState
from companion.navigation import rotations as rot
from companion.navigation.imu_noise import ImuNoise
from companion.navigation.ins_config import InsEkfConfig
from companion.navigation.ins_gps import StateHistory
from companion.navigation.local_frame import LocalFrame

CHI2_9999 = {1: 15.14, 2: 18.42, 3: 21.11, 4: 23.51, 5: 25.74, 6: 27.86}
P, V, TH, BA, BG = slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12), slice(12, 15)
_I15, _I3 = np.eye(15), np.eye(3)
_DIAG = np.diag_indices(15)
_SOLUTION_VALID = int(
    NavFlags.ATTITUDE_VALID | NavFlags.HEADING_VALID | NavFlags.VELOCITY_VALID
    | NavFlags.POSITION_VALID | NavFlags.ALTITUDE_VALID
)  # fmt: skip
_DEAD_RECKONING = int(NavFlags.DEAD_RECKONING)
_GPS_REJECTED = int(NavFlags.GPS_REJECTED)
_HEADING_REJECTED = int(NavFlags.HEADING_REJECTED)


class InsCore:
    """State, covariance, propagation and update; the aiding lives in ``InsEkf``."""

    def __init__(self, config: InsEkfConfig | None = None) -> None:
        self.cfg = c = config or InsEkfConfig()
        self.frame: LocalFrame | None = None
        self.aligned = False
        # Lists of floats, not arrays: they change on every IMU sample.
        self.p: list[float] = [0.0, 0.0, 0.0]
        self.v: list[float] = [0.0, 0.0, 0.0]
        self.q: rot.Quat = (1.0, 0.0, 0.0, 0.0)
        self.ba, self.bg = np.zeros(3), np.zeros(3)
        self.P = np.zeros((15, 15))
        self.g = np.array([0.0, 0.0, 9.80665])
        self.t_us: int | None = None
        self.rate: tuple[float, ...] = (0.0, 0.0, 0.0)
        self.history = StateHistory()
        self.noise = ImuNoise(c.noise_window_s, c.accel_noise, c.gyro_noise)
        self.last_gps_us: int | None = None  # the newest fix the filter accepted
        self.last_fix_us: int | None = None  # the newest usable fix received
        self.gps_rejected = self.heading_rejected = 0
        self.last_gps_ok = self.last_heading_ok = True
        self.cov_dt = 0.0
        self.cov_f: tuple[float, ...] = (0.0, 0.0, 0.0)
        self.cov_w: tuple[float, ...] = (0.0, 0.0, 0.0)
        self.cov_r: list[list[float]] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        self.walk_density = np.square([c.accel_bias_walk] * 3 + [c.gyro_bias_walk] * 3)

    # -- propagation ----------------------------------------------------------------
    def _integrate(self, dt: float, f: tuple[float, ...], w: tuple[float, ...]) -> None:
        # Plain floats: at 100-400 Hz numpy's per-call cost would dominate 3-vector sums.
        r = rot.rotation_matrix_rows(self.q)
        f0, f1, f2 = f
        p, v = self.p, self.v
        a = [row[0] * f0 + row[1] * f1 + row[2] * f2 for row in r]
        a[2] += self.g[2]
        half = 0.5 * dt * dt
        self.p = [p[i] + v[i] * dt + a[i] * half for i in range(3)]
        self.v = [v[i] + a[i] * dt for i in range(3)]
        dq = rot.rotation_vector_quaternion(w[0] * dt, w[1] * dt, w[2] * dt)
        self.q = rot.normalized(rot.multiply(self.q, dq))
        self.rate = w
        self.cov_dt += dt
        self.cov_f, self.cov_w, self.cov_r = f, w, r
        if self.cov_dt >= self.cfg.covariance_interval_s:
            self._flush_covariance()
        assert self.t_us is not None
        self.history.add(self.t_us, self.p, self.v)

    def _flush_covariance(self) -> None:
        """Bring P up to the nominal state's time (done in steps of a few IMU samples:
        at 100-400 Hz, propagating P on every sample costs more than it gains)."""
        dt = self.cov_dt
        if dt <= 0.0:
            return
        r, f, w = np.array(self.cov_r), np.array(self.cov_f), np.array(self.cov_w)
        phi = _I15.copy()
        phi[P, V] = _I3 * dt
        phi[V, TH] = -(r @ rot.skew(f)) * dt
        phi[V, BA] = -r * dt
        phi[TH, TH] = _I3 - rot.skew(w) * dt
        phi[TH, BG] = -_I3 * dt
        self.P = phi @ self.P @ phi.T
        accel, gyro = self.noise.densities()
        self.P[_DIAG] += np.concatenate(([0.0] * 3, [accel**2] * 3, [gyro**2] * 3,
                                         self.walk_density)) * dt  # fmt: skip
        self.cov_dt = 0.0

    # -- updates --------------------------------------------------------------------
    def _update(  # type: ignore[no-untyped-def]
        self, y: np.ndarray, h: np.ndarray, r: np.ndarray, k_mask=None, gate: bool = True
    ) -> bool:
        """Gate (unless told not to), then correct; False when the innovation was rejected.
        ``k_mask`` (15 booleans) limits which error states this measurement may correct."""
        self._flush_covariance()
        ph = self.P @ h.T
        s = h @ ph + r
        s_inv = np.linalg.inv(s)
        if gate and float(y @ s_inv @ y) > CHI2_9999[len(y)]:
            return False
        k = ph @ s_inv
        if k_mask is not None:
            k = k * k_mask[:, None]
        ikh = _I15 - k @ h
        self.P = ikh @ self.P @ ikh.T + k @ r @ k.T  # Joseph form: valid for any gain
        self._correct(k @ y)
        return True

    def _correct(self, dx: np.ndarray) -> None:
        self.p = (dx[P] + self.p).tolist()
        self.v = (dx[V] + self.v).tolist()
        self.q = rot.normalized(rot.multiply(self.q, rot.rotation_vector_quaternion(*dx[TH])))
        self.ba = self.ba + dx[BA]
        self.bg = self.bg + dx[BG]

    def _innovation_var(self, h: np.ndarray, r: float) -> float:
        self._flush_covariance()
        return float(h @ self.P @ h + r)

    def _reset_block(self, rows: slice | list[int], stds: list[float]) -> None:
        """Forget what the filter knew of some states: new variances, no correlations."""
        idx = list(range(15))[rows] if isinstance(rows, slice) else rows
        self.P[idx, :] = 0.0
        self.P[:, idx] = 0.0
        self.P[idx, idx] = np.square(stds)

    def _set_yaw(self, yaw: float, std: float) -> None:
        """Turn the attitude about the vertical to a new heading (a re-alignment)."""
        roll, pitch, _ = rot.quaternion_to_euler(self.q)
        self.q = rot.euler_to_quaternion(roll, pitch, yaw)
        tilt = np.sqrt(np.maximum(np.diag(self.P)[6:8], 0.0)).tolist()
        self._reset_block([6, 7, 8], [*tilt, std])

    # -- output ---------------------------------------------------------------------
    def state(self) -> NavState:
        """The solution at the last IMU sample."""
        msg = NavState(t_us=self.t_us or 0)
        msg.gps_rejected, msg.heading_rejected = self.gps_rejected, self.heading_rejected
        if not self.aligned or self.frame is None:
            msg.flags = int(NavFlags.ALIGNING)
            for name in ("roll_rad", "pitch_rad", "yaw_rad", "lat_deg", "lon_deg", "alt_msl_m"):
                setattr(msg, name, math.nan)
            return msg
        msg.q[:] = self.q
        msg.roll_rad, msg.pitch_rad, msg.yaw_rad = rot.quaternion_to_euler(self.q)
        msg.roll_rate_rad_s, msg.pitch_rate_rad_s, msg.yaw_rate_rad_s = self.rate
        msg.lat_deg, msg.lon_deg, msg.alt_msl_m = self.frame.geodetic(np.array(self.p))
        msg.vn_m_s, msg.ve_m_s, msg.vd_m_s = self.v
        std = np.sqrt(np.diag(self.P))
        msg.pos_std_m[:] = std[P].tolist()
        msg.vel_std_m_s[:] = std[V].tolist()
        msg.att_std_rad[:] = std[TH].tolist()
        msg.accel_bias_m_s2[:] = self.ba.tolist()
        msg.gyro_bias_rad_s[:] = self.bg.tolist()
        msg.flags = self._flags()
        return msg

    def _flags(self) -> int:
        flags = _SOLUTION_VALID
        t = self.t_us or 0
        # Dead reckoning means no fix is coming; fixes that come but are rejected say so
        # in GPS_REJECTED (and reset the filter to GPS after ``reset_after`` of them).
        if self.last_fix_us is None or (t - self.last_fix_us) / 1e6 > self.cfg.gps_timeout_s:
            flags |= _DEAD_RECKONING
        if not self.last_gps_ok:
            flags |= _GPS_REJECTED
        if not self.last_heading_ok:
            flags |= _HEADING_REJECTED
        return flags
