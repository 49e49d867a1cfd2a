"""Heading from GPS velocity alone: a Gaussian-sum filter over a bank of yaw hypotheses.

The idea is that of PX4 EKF2's emergency yaw estimator (Riseborough's "EKF-GSF"), written
anew here. When the aircraft accelerates (a turn, a take-off, a speed change), the horizontal
specific force the IMU measures, turned to north-east with the right heading, integrates to
the velocity GPS measures; with a wrong heading it does not. One small filter per hypothesis,
state [vn, ve, yaw], spread evenly round the circle at the start, each integrating the levelled
accelerometer with its own yaw and corrected by GPS velocity. Each filter's weight follows how
likely its innovations are; the weighted circular mean of the yaws is the heading and the
spread of the hypotheses (plus their own variance) its uncertainty. It needs no magnetometer
and no initial heading, so it is what a navigator that has lost its heading (or never had a
good one) can re-align from.

Tilt comes from the caller (the INS's roll and pitch): near-level flight is where the
horizontal specific force matters, and a tilt error of a few degrees moves it by g·sin of that,
allowed for in the velocity process noise. Pure library: numbers and dt in, numbers out.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

MODELS = 5
ACCEL_NOISE = 1.0  # m/s² (1-σ): tilt errors of ~10° and vibration in the levelled force
YAW_RATE_NOISE = 0.015  # rad/s (1-σ): gyro bias and the tilt error's part in the yaw rate
MIN_WEIGHT = 1e-4  # no hypothesis dies for good: a later manoeuvre may favour it again
MAX_NIS = 50.0  # a single wild fix must not kill every hypothesis but one
_Q_VEL, _Q_YAW = ACCEL_NOISE**2, YAW_RATE_NOISE**2  # process noise per second of integration


class _Model:
    """One hypothesis: state [vn, ve, yaw] and its 3×3 covariance, as plain floats.

    Floats, not a (models, 3, 3) array: with five models numpy's cost per call, a dozen
    calls per step, was nearly all of the bank's time (about 40 µs a predict, 190 µs an
    update, against a few µs written out).
    """

    __slots__ = ("cov", "ve", "vn", "yaw")

    def __init__(self, vn: float, ve: float, yaw: float, cov: list[list[float]]) -> None:
        self.vn, self.ve, self.yaw = vn, ve, yaw
        self.cov = cov  # 3×3, rows

    def predict(self, dt: float, f_fwd: float, f_right: float, yaw_turn: float) -> None:
        """Integrate the levelled specific force with this model's yaw; Φ·P·Φᵀ + Q·dt,
        Φ being the identity but for the velocities' dependence on the yaw."""
        cy, sy = math.cos(self.yaw), math.sin(self.yaw)
        a_n = cy * f_fwd - sy * f_right
        a_e = sy * f_fwd + cy * f_right
        self.vn += a_n * dt
        self.ve += a_e * dt
        self.yaw = _wrap(self.yaw + yaw_turn)
        c0, c1 = -a_e * dt, a_n * dt  # Φ[0][2], Φ[1][2]
        (p00, p01, p02), (p10, p11, p12), (p20, p21, p22) = self.cov
        # A = Φ·P (rows 0 and 1 take c times row 2), then A·Φᵀ (columns likewise).
        a00, a01, a02 = p00 + c0 * p20, p01 + c0 * p21, p02 + c0 * p22
        a10, a11, a12 = p10 + c1 * p20, p11 + c1 * p21, p12 + c1 * p22
        self.cov = [
            [a00 + a02 * c0 + _Q_VEL * dt, a01 + a02 * c1, a02],
            [a10 + a12 * c0, a11 + a12 * c1 + _Q_VEL * dt, a12],
            [p20 + p22 * c0, p21 + p22 * c1, p22 + _Q_YAW * dt],
        ]

    def update(self, vn: float, ve: float, var: float) -> float:
        """Correct by a GPS velocity (variance ``var`` per axis); the innovation's likelihood."""
        (p00, p01, _), (p10, p11, _), (p20, p21, _) = self.cov
        y0, y1 = vn - self.vn, ve - self.ve
        s00, s01, s10, s11 = p00 + var, p01, p10, p11 + var
        det = s00 * s11 - s01 * s10
        i00, i01, i10, i11 = s11 / det, -s01 / det, -s10 / det, s00 / det
        nis = y0 * (i00 * y0 + i01 * y1) + y1 * (i10 * y0 + i11 * y1)
        likelihood = math.exp(-0.5 * min(nis, MAX_NIS)) / (math.tau * math.sqrt(det))
        # K = P[:, :2]·S⁻¹ (3×2)
        k00, k01 = p00 * i00 + p01 * i10, p00 * i01 + p01 * i11
        k10, k11 = p10 * i00 + p11 * i10, p10 * i01 + p11 * i11
        k20, k21 = p20 * i00 + p21 * i10, p20 * i01 + p21 * i11
        self.vn += k00 * y0 + k01 * y1
        self.ve += k10 * y0 + k11 * y1
        self.yaw = _wrap(self.yaw + k20 * y0 + k21 * y1)
        self.cov = _joseph(self.cov, ((k00, k01), (k10, k11), (k20, k21)), var)
        return likelihood


def _joseph(
    cov: list[list[float]], k: tuple[tuple[float, float], ...], var: float
) -> list[list[float]]:
    """(I - K·H)·P·(I - K·H)ᵀ + K·R·Kᵀ, H picking vn and ve, R = var·I: valid for any gain.
    Written out (no generators: each costs about a microsecond, 18 of them per model)."""
    (k00, k01), (k10, k11), (k20, k21) = k
    # I - K·H: the identity with K's columns subtracted from its first two columns.
    e = ((1.0 - k00, -k01), (-k10, 1.0 - k11), (-k20, -k21))
    (p00, p01, p02), (p10, p11, p12), (p20, p21, p22) = cov
    (e00, e01), (e10, e11), (e20, e21) = e
    a = (
        (e00 * p00 + e01 * p10, e00 * p01 + e01 * p11, e00 * p02 + e01 * p12),
        (e10 * p00 + e11 * p10, e10 * p01 + e11 * p11, e10 * p02 + e11 * p12),
        (e20 * p00 + e21 * p10 + p20, e20 * p01 + e21 * p11 + p21, e20 * p02 + e21 * p12 + p22),
    )
    out = []
    for (a0, a1, a2), (ki0, ki1) in zip(a, k, strict=True):
        out.append([
            a0 * e00 + a1 * e01 + var * (ki0 * k00 + ki1 * k01),
            a0 * e10 + a1 * e11 + var * (ki0 * k10 + ki1 * k11),
            a0 * e20 + a1 * e21 + a2 + var * (ki0 * k20 + ki1 * k21),
        ])  # fmt: skip
    return out


def _wrap(angle: float) -> float:
    """An angle to [-π, π) (Python's float % takes the divisor's sign, as np.remainder)."""
    return (angle + math.pi) % math.tau - math.pi


class YawGsf:
    """The bank of yaw hypotheses; ``heading()`` is its verdict."""

    def __init__(self, models: int = MODELS) -> None:
        self.n = models
        self.models: list[_Model] = []
        self.w = [1.0 / models] * models
        self.started = False

    def start(self, vn: float, ve: float, vel_std: float) -> None:
        """Spread the hypotheses round the circle, all starting at the GPS velocity."""
        spread = math.pi / self.n  # half the gap between neighbours
        var, yaw_var = vel_std**2, spread**2
        self.models = [
            _Model(vn, ve, i * math.tau / self.n - math.pi,
                   [[var, 0.0, 0.0], [0.0, var, 0.0], [0.0, 0.0, yaw_var]])
            for i in range(self.n)
        ]  # fmt: skip
        self.w = [1.0 / self.n] * self.n
        self.started = True

    def predict(self, dt: float, accel_body: Sequence[float], gyro_body: Sequence[float],
                roll: float, pitch: float) -> None:  # fmt: skip
        """Integrate dt seconds of the (bias-corrected) specific force and angular rate."""
        if not self.started or dt <= 0.0:
            return
        sr, cr, sp, cp = math.sin(roll), math.cos(roll), math.sin(pitch), math.cos(pitch)
        fx, fy, fz = accel_body
        # The specific force in a frame turned by roll and pitch only (the yaw is ours).
        f_fwd = fx * cp + fy * sr * sp + fz * cr * sp
        f_right = fy * cr - fz * sr
        _, q_rate, r_rate = gyro_body
        yaw_rate = (q_rate * sr + r_rate * cr) / max(cp, 0.1)
        for model in self.models:
            model.predict(dt, f_fwd, f_right, yaw_rate * dt)

    def update(self, vn: float, ve: float, vel_std: float) -> None:
        """Correct every hypothesis with a GPS velocity and re-weigh them by its likelihood."""
        if not (math.isfinite(vn) and math.isfinite(ve)):
            return
        if not self.started:
            self.start(vn, ve, vel_std)
            return
        var = vel_std**2
        w = [wi * m.update(vn, ve, var) for wi, m in zip(self.w, self.models, strict=True)]
        total = sum(w)
        if total > 0.0 and math.isfinite(total):
            floored = [max(wi / total, MIN_WEIGHT) for wi in w]
            norm = sum(floored)
            self.w = [wi / norm for wi in floored]

    def heading(self) -> tuple[float, float] | None:
        """(yaw, 1-σ) in radians, or None before the first GPS velocity."""
        if not self.started:
            return None
        pairs = list(zip(self.w, self.models, strict=True))
        mean = math.atan2(
            sum(w * math.sin(m.yaw) for w, m in pairs),
            sum(w * math.cos(m.yaw) for w, m in pairs),
        )
        var = sum(w * (_wrap(m.yaw - mean) ** 2 + m.cov[2][2]) for w, m in pairs)
        return mean, math.sqrt(var)
