"""The INS's state, its propagation by the IMU and the Kalman update (``ins_ekf`` uses it).

Nominal state: position and velocity in a local NED frame, attitude as a body→NED
quaternion, accelerometer and gyro biases. Error state δx = [δp, δv, δθ (body), δb_a, δb_g].
"""

from __future__ import annotations

import ctypes
import math
import struct

import numpy as np

from companion.messages import NavFlags, NavState
from companion.messages.navigation import NAV_DEAD_RECKONING, NAV_GPS_REJECTED, NAV_HEADING_REJECTED
from companion.navigation import rotations as rot
from companion.navigation.imu_noise import ImuNoise
from companion.navigation.ins_config import InsEkfConfig
from companion.navigation.ins_gps import StateHistory
from companion.navigation.local_frame import LocalFrame

CHI2_9999 = {1: 15.14, 2: 18.42, 3: 21.11, 4: 23.51, 5: 25.74, 6: 27.86}
P, V, TH, BA, BG = slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12), slice(12, 15)
_I15 = np.eye(15)
# Where ``_flush_covariance`` writes Φ's entries besides δv/δθ: δp/δv (diagonal), δv/δb_a,
# δθ/δθ (off the diagonal) and δθ/δb_g, in the order it lists them.
_PHI_FLAT = np.ravel_multi_index(
    (
        [0, 1, 2, *[3] * 3, *[4] * 3, *[5] * 3, 6, 6, 7, 7, 8, 8, *[6] * 3, *[7] * 3, *[8] * 3],
        [3, 4, 5, *[9, 10, 11] * 3, 7, 8, 6, 8, 6, 7, *[12, 13, 14] * 3],
    ),
    (15, 15),
)
# A solution made in one call from its packed fields: setting the message's two dozen fields
# and arrays one by one through ctypes cost twice the rest of ``state()``, at every
# publication. NavState's native layout: t_us, q, 12 doubles, the five 3-vectors of
# standard deviations and biases, flags and the two rejection counts, padding.
_STATE_PACK = struct.Struct("=q4d12d15d3I4x")
assert _STATE_PACK.size == ctypes.sizeof(NavState)
_nav_state = NavState.from_buffer_copy
_U32 = 0xFFFFFFFF  # a ctypes c_uint32 field keeps the low 32 bits; struct would refuse more
_SOLUTION_VALID = int(
    NavFlags.ATTITUDE_VALID | NavFlags.HEADING_VALID | NavFlags.VELOCITY_VALID
    | NavFlags.POSITION_VALID | NavFlags.ALTITUDE_VALID
)  # fmt: skip


def _picker(rows: list[int]) -> slice | list[int]:
    """Consecutive states as a slice: a view costs a fraction of numpy's fancy indexing."""
    first = rows[0]
    return slice(first, first + len(rows)) if rows == [*range(first, first + len(rows))] else rows


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
        # Floats too: a numpy scalar taken from an array makes every sum it enters, the
        # quaternion's included, a numpy scalar (several times slower than a float).
        self.ba: list[float] = [0.0, 0.0, 0.0]
        self.bg: list[float] = [0.0, 0.0, 0.0]
        self.P = np.zeros((15, 15))
        self.g: list[float] = [0.0, 0.0, 9.80665]
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
        self.walk_density = [c.accel_bias_walk**2] * 3 + [c.gyro_bias_walk**2] * 3

    # -- propagation ----------------------------------------------------------------
    def _integrate(self, dt: float, f: tuple[float, ...], w: tuple[float, ...]) -> None:
        # Plain floats: at 100-400 Hz numpy's per-call cost would dominate 3-vector sums.
        # Written out, not looped: the same sums in the same order, without the loops' cost.
        r = rot.rotation_matrix_rows(self.q)
        (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = r
        f0, f1, f2 = f
        p0, p1, p2 = self.p
        v0, v1, v2 = self.v
        a0 = r00 * f0 + r01 * f1 + r02 * f2
        a1 = r10 * f0 + r11 * f1 + r12 * f2
        a2 = r20 * f0 + r21 * f1 + r22 * f2 + self.g[2]
        half = 0.5 * dt * dt
        self.p = [p0 + v0 * dt + a0 * half, p1 + v1 * dt + a1 * half, p2 + v2 * dt + a2 * half]
        self.v = [v0 + a0 * dt, v1 + a1 * dt, v2 + a2 * dt]
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
        r = np.array(self.cov_r)
        w0, w1, w2 = self.cov_w
        phi = _I15.copy()
        phi[V, TH] = (r @ rot.skew(self.cov_f)) * -dt  # a matrix product: BLAS rounding kept
        # The rest of Φ in one scatter (a numpy call per block costs more than the sums).
        nd = -dt
        (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = self.cov_r
        # Written out: a generator over the nine entries cost more than the products.
        phi.flat[_PHI_FLAT] = [
            dt, dt, dt,
            r00 * nd, r01 * nd, r02 * nd, r10 * nd, r11 * nd, r12 * nd,
            r20 * nd, r21 * nd, r22 * nd,
            w2 * dt, -(w1 * dt), -(w2 * dt), w0 * dt, w1 * dt, -(w0 * dt),
            nd, -0.0, -0.0, -0.0, nd, -0.0, -0.0, -0.0, nd,
        ]  # fmt: skip
        self.P = phi @ self.P @ phi.T  # a fresh C-contiguous array: ravel() is a view of it
        accel, gyro = self.noise.densities()
        qa, qg = accel**2 * dt, gyro**2 * dt
        self.P.ravel()[::16] += [0.0, 0.0, 0.0, qa, qa, qa, qg, qg, qg,
                                 *[d * dt for d in self.walk_density]]  # fmt: skip
        self.cov_dt = 0.0

    # -- updates --------------------------------------------------------------------
    def _update(
        self, y: np.ndarray, h: np.ndarray | list[int], r: np.ndarray,
        k_mask: np.ndarray | None = None, gate: bool = True,
    ) -> bool:  # fmt: skip
        """Gate (unless told not to), then correct; False when the innovation was rejected.
        ``h``: the Jacobian, or the list of states measured directly (rows of the identity:
        picking them out gives the same numbers as multiplying, with fewer numpy calls).
        ``k_mask`` (15 booleans) limits which error states this measurement may correct."""
        self._flush_covariance()
        rows = None
        if isinstance(h, list):
            rows = _picker(h)
            ph = self.P[:, rows]
            s = ph[rows] + r
        else:
            ph = self.P @ h.T
            s = h @ ph + r
        # One measurement (the barometer, a heading, the yaw-rate bias standing still): but
        # for Joseph's two, every product below has an inner dimension of one, a single
        # multiplication an entry, so it is written as an elementwise one (the same
        # numbers; a matrix product's numpy call costs many times its arithmetic), and
        # the gate in floats. 1×1: inv is 1/s exactly.
        one = len(y) == 1
        s_inv = 1.0 / s if one else np.linalg.inv(s)
        if one:
            y0 = float(y[0])
            nis = y0 * float(s_inv[0, 0]) * y0
        else:
            nis = float(y @ s_inv @ y)
        if gate and nis > CHI2_9999[len(y)]:
            return False
        k = ph * s_inv if one else ph @ s_inv
        if k_mask is not None:
            k = k * k_mask[:, None]
        if rows is None:
            ikh = _I15 - (k * h if one else k @ h)
        else:
            ikh = _I15.copy()
            ikh[:, rows] -= k
        gain_noise = (k * r) * k.T if one else k @ r @ k.T
        self.P = ikh @ self.P @ ikh.T + gain_noise  # Joseph form: valid for any gain
        self._correct(k[:, 0] * y0 if one else k @ y)
        return True

    def _correct(self, dx: np.ndarray) -> None:
        # As floats: a numpy scalar in the quaternion would make every later IMU sample's
        # arithmetic numpy scalar arithmetic (the same numbers, several times slower).
        d = dx.tolist()
        p, v, ba, bg = self.p, self.v, self.ba, self.bg
        self.p = [d[0] + p[0], d[1] + p[1], d[2] + p[2]]
        self.v = [d[3] + v[0], d[4] + v[1], d[5] + v[2]]
        self.q = rot.normalized(rot.multiply(self.q, rot.rotation_vector_quaternion(*d[6:9])))
        self.ba = [d[9] + ba[0], d[10] + ba[1], d[11] + ba[2]]
        self.bg = [d[12] + bg[0], d[13] + bg[1], d[14] + bg[2]]

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
        if not self.aligned or self.frame is None:
            msg = NavState(t_us=self.t_us or 0)
            msg.gps_rejected, msg.heading_rejected = self.gps_rejected, self.heading_rejected
            msg.flags = int(NavFlags.ALIGNING)
            for name in ("roll_rad", "pitch_rad", "yaw_rad", "lat_deg", "lon_deg", "alt_msl_m"):
                setattr(msg, name, math.nan)
            return msg
        # math.sqrt rounds as np.sqrt does; np.diag's own cost was most of this line.
        std = [math.sqrt(v) if v >= 0.0 else math.nan for v in self.P.diagonal()[:9].tolist()]
        return _nav_state(
            _STATE_PACK.pack(
                self.t_us or 0, *self.q, *rot.quaternion_to_euler(self.q), *self.rate,
                *self.frame.geodetic(self.p), *self.v, *std, *self.bg, *self.ba,
                self._flags() & _U32, self.gps_rejected & _U32, self.heading_rejected & _U32,
            )
        )  # fmt: skip

    def _flags(self) -> int:
        flags = _SOLUTION_VALID
        t = self.t_us or 0
        # Dead reckoning means no fix is coming; fixes that come but are rejected say so
        # in GPS_REJECTED (and reset the filter to GPS after ``reset_after`` of them).
        if self.last_fix_us is None or (t - self.last_fix_us) / 1e6 > self.cfg.gps_timeout_s:
            flags |= NAV_DEAD_RECKONING
        if not self.last_gps_ok:
            flags |= NAV_GPS_REJECTED
        if not self.last_heading_ok:
            flags |= NAV_HEADING_REJECTED
        return flags
