"""Strapdown INS with a 15-state error-state extended Kalman filter.

Nominal state: position and velocity in a local NED frame (``LocalFrame``, about the first
fix), attitude as a body→NED quaternion, accelerometer and gyro biases. Error state
δx = [δp, δv, δθ (body frame), δb_a, δb_g]. The IMU drives the prediction with the true
time between samples and WGS-84 normal gravity; GPS position and velocity and a heading
(compass, or the tilt-compensated magnetometer) correct it. Every update passes an
innovation gate (normalised innovation squared against the χ² 99.99 % point): outliers
are rejected and counted, and after ``reset_after`` GPS rejections in a row the position
and velocity are reset to GPS rather than trusted forever. Without GPS the INS dead
reckons, its uncertainty growing. GPS fixes that lag the IMU are compared with the state
of ``gps_delay_s`` earlier. Earth rotation and transport rate are not modelled (below a
consumer IMU's noise).

Feed samples in time order (``on_imu``, ``on_gps``, ``on_compass``, ``on_mag``);
``state()`` is the solution at the last IMU sample.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from companion.messages import Baro, Compass, GpsFix, Imu, Magnetometer, NavFlags, NavState
from companion.navigation import rotations as rot
from companion.navigation.baro_datum import BaroDatum
from companion.navigation.ins_align import Aligner, Alignment
from companion.navigation.local_frame import LocalFrame, normal_gravity

CHI2_9999 = {1: 15.14, 2: 18.42, 3: 21.11, 4: 23.51, 5: 25.74, 6: 27.86}
MAX_IMU_GAP_S = 0.5
HISTORY_S = 1.0
COMPASS_TILT_TO_HEADING = 3.0
JACOBIAN_STEP = 1e-4
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


@dataclass(frozen=True)
class InsEkfConfig:
    """Noise densities, initial uncertainties, gates. Defaults: a MEMS IMU (VN-100 class)."""

    # Noise densities a little above a VN-100's datasheet (0.14 mg/√Hz, 0.0035 °/s/√Hz):
    # much larger values let a heading update drag the tilt about during GPS outages.
    accel_noise: float = 0.01  # m/s² / √Hz (velocity random walk)
    gyro_noise: float = 5e-4  # rad/s / √Hz (angle random walk)
    accel_bias_walk: float = 1e-3  # m/s² / √s
    gyro_bias_walk: float = 5e-5  # rad/s / √s
    accel_bias_std: float = 0.1  # initial 1-σ
    gyro_bias_std: float = math.radians(0.5)
    gps_pos_std: float = 3.0  # when the fix carries no accuracy
    gps_vel_std: float = 0.3
    baro_std: float = 0.5  # m, barometric height over seconds
    baro_interval_s: float = 0.1
    baro_timeout_s: float = 1.0  # barometer silent this long: GPS height again
    baro_offset_tau_s: float = 300.0  # how slowly GPS pulls the barometer's datum
    gps_vert_with_baro_std: float = 10.0  # GPS height still anchors the datum, weakly
    compass_std: float = math.radians(2.0)
    mag_heading_std: float = math.radians(4.0)
    declination_deg: float = 0.0  # for magnetometer headings
    gps_delay_s: float = 0.0
    gps_timeout_s: float = 2.0
    heading_timeout_s: float = 1.0  # magnetometer silent this long: use the compass
    reset_after: int = 10
    heading_interval_s: float = 0.2  # magnetometer heading updates at most this often
    covariance_interval_s: float = 0.04
    align_window_s: float = 0.5


class InsEkf:
    """The navigator; see the module doc."""

    def __init__(self, config: InsEkfConfig | None = None) -> None:
        self.cfg = config or InsEkfConfig()
        self.frame: LocalFrame | None = None
        self.aligner = Aligner(self.cfg.align_window_s, 9.80665)
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
        self.history: deque[tuple[int, np.ndarray, np.ndarray]] = deque()
        self.last_gps_us: int | None = None
        self.last_compass: Compass | None = None
        self.last_mag: np.ndarray | None = None
        self.last_mag_us: int | None = None
        self.pending_fix: GpsFix | None = None
        self.gps_rejected = self.heading_rejected = self.gps_reject_run = 0
        self.last_gps_ok = self.last_heading_ok = True
        self.resets = 0
        self.next_heading_us = 0
        c0 = self.cfg
        self.baro = BaroDatum(c0.baro_interval_s, c0.baro_timeout_s, c0.baro_offset_tau_s)
        self.cov_dt = 0.0
        self.cov_f: tuple[float, ...] = (0.0, 0.0, 0.0)
        self.cov_w: tuple[float, ...] = (0.0, 0.0, 0.0)
        self.cov_r: list[list[float]] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        c = self.cfg
        self.q_density = np.repeat(
            np.square([0.0, c.accel_noise, c.gyro_noise, c.accel_bias_walk, c.gyro_bias_walk]), 3
        )

    # -- inputs ---------------------------------------------------------------------
    def on_imu(self, imu: Imu) -> None:
        """Propagate to the sample's time (or collect it for the alignment)."""
        values = (imu.ax_m_s2, imu.ay_m_s2, imu.az_m_s2, imu.gx_rad_s, imu.gy_rad_s, imu.gz_rad_s)
        if not math.isfinite(sum(values)):
            return
        if not self.aligned:
            self._collect(imu.t_us, np.array(values[:3]), np.array(values[3:]))
            return
        dt = (imu.t_us - self.t_us) / 1e6 if self.t_us is not None else 0.0
        self.t_us = imu.t_us
        if dt <= 0.0:
            return
        if dt > MAX_IMU_GAP_S:  # a hole in the data: time passes, nothing is integrated
            self._flush_covariance()
            self.cov_dt = dt
            self._flush_covariance()
            return
        ba, bg = self.ba, self.bg
        f = (values[0] - ba[0], values[1] - ba[1], values[2] - ba[2])
        w = (values[3] - bg[0], values[4] - bg[1], values[5] - bg[2])
        self._integrate(dt, f, w)

    def on_gps(self, fix: GpsFix) -> None:
        """Position and velocity update (or the first fix, which anchors the frame)."""
        if fix.fix_type < 2 or not (math.isfinite(fix.lat_deg) and math.isfinite(fix.lon_deg)):
            return
        if self.frame is None:
            alt = fix.alt_msl_m if math.isfinite(fix.alt_msl_m) else 0.0
            self.frame = LocalFrame(fix.lat_deg, fix.lon_deg, alt)
            self.g[2] = self.aligner.g = normal_gravity(fix.lat_deg, alt)
        if not self.aligned:
            self.pending_fix = fix
            return
        self._gps_update(fix)

    def on_baro(self, reading: Baro) -> None:
        """Barometric height: the vertical channel follows it; GPS only moves its datum."""
        if not self.aligned:
            return
        up = self.baro.height(reading.alt_rel_m, reading.t_us, self.p[2])
        if up is not None:
            y = np.array([-up - self.p[2]])
            self._update(y, _I15[[2]], np.array([[self.cfg.baro_std**2]]))

    def on_compass(self, reading: Compass) -> None:
        """Heading update from a digital compass (heading already true), when no
        magnetometer speaks.

        The compass levels itself with its accelerometer, so in turns its tilt, and with it
        its heading, is off; how far its tilt is from ours says by how much (the heading
        error is about the tilt error times tan(inclination), ~3 at mid latitudes).
        """
        self.last_compass = reading
        if not self.aligned or self._fresh(self.last_mag_us, reading.t_us):
            return
        roll, pitch, _ = rot.quaternion_to_euler(self.q)
        tilt_error = math.hypot(reading.roll_rad - roll, reading.pitch_rad - pitch)
        std = math.hypot(self.cfg.compass_std, COMPASS_TILT_TO_HEADING * tilt_error)
        self._heading_update(reading.heading_rad, std)

    def on_mag(self, reading: Magnetometer) -> None:
        """Heading update from the magnetometer, levelled with our own attitude."""
        values = (reading.mx_gauss, reading.my_gauss, reading.mz_gauss)
        if not math.isfinite(sum(values)):
            return
        mag = np.array(values)
        self.last_mag, self.last_mag_us = mag, reading.t_us
        if not self.aligned or reading.t_us < self.next_heading_us:
            return
        self.next_heading_us = reading.t_us + round(self.cfg.heading_interval_s * 1e6)
        decl = math.radians(self.cfg.declination_deg)
        g0 = _mag_residual(self.q, mag, decl)
        # The heading is levelled with our own tilt, so it depends on roll and pitch too:
        # the Jacobian says how (about tan(inclination) per radian), and the filter then
        # blames a disagreement on tilt or heading in the right measure instead of
        # turning every tilt error into a heading error.
        h = np.zeros((1, 15))
        for axis in range(3):
            nudge = [0.0, 0.0, 0.0]
            nudge[axis] = JACOBIAN_STEP
            q = rot.multiply(self.q, rot.rotation_vector_quaternion(*nudge))
            h[0, 6 + axis] = (
                math.remainder(_mag_residual(q, mag, decl) - g0, math.tau) / JACOBIAN_STEP
            )
        ok = self._update(np.array([-g0]), h, np.array([[self.cfg.mag_heading_std**2]]))
        self.last_heading_ok = ok
        if not ok:
            self.heading_rejected += 1

    # -- alignment ------------------------------------------------------------------
    def _collect(self, t_us: int, accel: np.ndarray, gyro: np.ndarray) -> None:
        self.t_us = t_us
        self.aligner.add_imu(t_us, accel, gyro)
        fix = self.pending_fix
        if fix is None:
            return
        compass = self.last_compass
        fresh = compass is not None and self._fresh(compass.t_us, t_us)
        heading = compass.heading_rad if compass is not None and fresh else None
        mag = self.last_mag if self._fresh(self.last_mag_us, t_us) else None
        vel = np.array((fix.vn_m_s, fix.ve_m_s, fix.vd_m_s))
        decl = math.radians(self.cfg.declination_deg)
        found = self.aligner.align(vel, heading, mag, decl)
        if found is not None:
            self._start(found, fix, vel)

    def _start(self, a: Alignment, fix: GpsFix, vel: np.ndarray) -> None:
        assert self.frame is not None
        self.p = self._fix_position(fix).tolist()
        self.v = np.nan_to_num(vel).tolist()
        self.q = rot.euler_to_quaternion(a.roll, a.pitch, a.yaw)
        pos_std = fix.eph_m if math.isfinite(fix.eph_m) else self.cfg.gps_pos_std
        c = self.cfg
        diag = [pos_std] * 2 + [pos_std * 1.5] + [max(c.gps_vel_std, 0.5)] * 3
        diag += [a.tilt_std, a.tilt_std, a.yaw_std]
        diag += [c.accel_bias_std] * 3 + [c.gyro_bias_std] * 3
        self.P = np.diag(np.square(diag))
        self.aligned = True
        self.last_gps_us = fix.t_us

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
        self.history.append((self.t_us, self.p, self.v))
        if self.history[0][0] < self.t_us - HISTORY_S * 1e6:
            self.history.popleft()

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
        self.P[_DIAG] += self.q_density * dt
        self.cov_dt = 0.0

    # -- updates --------------------------------------------------------------------
    def _update(self, y: np.ndarray, h: np.ndarray, r: np.ndarray) -> bool:
        """Gate, then correct; False when the innovation was rejected."""
        self._flush_covariance()
        ph = self.P @ h.T
        s = h @ ph + r
        s_inv = np.linalg.inv(s)
        if float(y @ s_inv @ y) > CHI2_9999[len(y)]:
            return False
        k = ph @ s_inv
        ikh = _I15 - k @ h
        self.P = ikh @ self.P @ ikh.T + k @ r @ k.T  # Joseph form: stays symmetric, positive
        dx = k @ y
        self.p = (dx[P] + self.p).tolist()
        self.v = (dx[V] + self.v).tolist()
        self.q = rot.normalized(rot.multiply(self.q, rot.rotation_vector_quaternion(*dx[TH])))
        self.ba = self.ba + dx[BA]
        self.bg = self.bg + dx[BG]
        return True

    def _fix_position(self, fix: GpsFix) -> np.ndarray:
        assert self.frame is not None
        alt = fix.alt_msl_m if math.isfinite(fix.alt_msl_m) else self.frame.ref[2]
        return self.frame.ned(fix.lat_deg, fix.lon_deg, alt)

    def _state_at(self, t_us: int) -> tuple[np.ndarray, np.ndarray]:
        """Nominal position and velocity at an earlier time (for lagging fixes)."""
        for t, p, v in reversed(self.history):
            if t <= t_us:
                return np.array(p), np.array(v)
        return np.array(self.p), np.array(self.v)

    def _gps_update(self, fix: GpsFix) -> None:
        z_p = self._fix_position(fix)
        z_v = np.array((fix.vn_m_s, fix.ve_m_s, fix.vd_m_s))
        p_then, v_then = self._state_at(fix.t_us - round(self.cfg.gps_delay_s * 1e6))
        std = fix.eph_m if math.isfinite(fix.eph_m) and fix.eph_m > 0 else self.cfg.gps_pos_std
        vstd = fix.epv_m if math.isfinite(fix.epv_m) and fix.epv_m > 0 else 1.5 * std
        if self.baro.fresh(fix.t_us):
            since = (fix.t_us - self.last_gps_us) / 1e6 if self.last_gps_us is not None else 0.0
            self.baro.follow_gps(z_p[2], self.p[2], since)
            vstd = max(vstd, self.cfg.gps_vert_with_baro_std)
        rows = [0, 1] + ([2] if math.isfinite(fix.alt_msl_m) else [])
        rows += [3 + i for i in range(3) if math.isfinite(z_v[i])]
        y_all = np.concatenate([z_p - p_then, z_v - v_then])
        c = self.cfg
        vd_std = fix.vd_std_m_s if fix.vd_std_m_s > 0 else c.gps_vel_std  # NaN > 0 is False
        sig = np.array([std, std, vstd, c.gps_vel_std, c.gps_vel_std, vd_std])
        h = _I15[rows]
        ok = self._update(y_all[rows], h, np.diag(np.square(sig[rows])))
        self.last_gps_ok = ok
        if ok:
            self.gps_reject_run = 0
            self.last_gps_us = fix.t_us
            return
        self.gps_rejected += 1
        self.gps_reject_run += 1
        if self.gps_reject_run >= self.cfg.reset_after:
            self._reset_to_gps(z_p, z_v, std)

    def _reset_to_gps(self, z_p: np.ndarray, z_v: np.ndarray, std: float) -> None:
        """The INS has disagreed with GPS for too long: believe GPS, and say so."""
        self.p = z_p.tolist()
        self.v = np.where(np.isfinite(z_v), z_v, self.v).tolist()
        self.P[:6, :] = 0.0
        self.P[:, :6] = 0.0
        self.P[:6, :6] = np.diag(np.square([std] * 3 + [self.cfg.gps_vel_std * 2] * 3))
        self.gps_reject_run = 0
        self.resets += 1

    def _heading_update(self, heading: float, std: float) -> None:
        r = rot.rotation_matrix(self.q)
        den = r[0, 0] ** 2 + r[1, 0] ** 2
        if den < 1e-6:  # pointing straight up or down: heading undefined
            return
        yaw = math.atan2(r[1, 0], r[0, 0])
        h = np.zeros((1, 15))
        h[0, 7] = (r[0, 2] * r[1, 0] - r[1, 2] * r[0, 0]) / den
        h[0, 8] = (r[1, 1] * r[0, 0] - r[0, 1] * r[1, 0]) / den
        y = np.array([math.remainder(heading - yaw, math.tau)])
        ok = self._update(y, h, np.array([[std * std]]))
        self.last_heading_ok = ok
        if not ok:
            self.heading_rejected += 1

    def _fresh(self, then_us: int | None, now_us: int) -> bool:
        return then_us is not None and (now_us - then_us) / 1e6 < self.cfg.heading_timeout_s

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
        if self.last_gps_us is None or (t - self.last_gps_us) / 1e6 > self.cfg.gps_timeout_s:
            flags |= _DEAD_RECKONING
        if not self.last_gps_ok:
            flags |= _GPS_REJECTED
        if not self.last_heading_ok:
            flags |= _HEADING_REJECTED
        return flags


def _mag_residual(q: rot.Quat, mag: np.ndarray, declination: float) -> float:
    """Magnetometer heading (levelled with q's tilt) minus q's heading, wrapped."""
    roll, pitch, yaw = rot.quaternion_to_euler(q)
    heading = rot.tilt_compensated_heading(mag, roll, pitch) + declination
    return math.remainder(heading - yaw, math.tau)
