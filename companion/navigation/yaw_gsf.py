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

import numpy as np

MODELS = 5
ACCEL_NOISE = 1.0  # m/s² (1-σ): tilt errors of ~10° and vibration in the levelled force
YAW_RATE_NOISE = 0.015  # rad/s (1-σ): gyro bias and the tilt error's part in the yaw rate
MIN_WEIGHT = 1e-4  # no hypothesis dies for good: a later manoeuvre may favour it again
MAX_NIS = 50.0  # a single wild fix must not kill every hypothesis but one
_I3 = np.eye(3)
# The process noise per second of integration (diagonal); built once, scaled by dt.
_Q_PER_S = np.diag([ACCEL_NOISE**2, ACCEL_NOISE**2, YAW_RATE_NOISE**2])


class YawGsf:
    """The bank of yaw hypotheses; ``heading()`` is its verdict."""

    def __init__(self, models: int = MODELS) -> None:
        self.n = models
        self.x = np.zeros((models, 3))  # vn, ve, yaw per hypothesis
        self.P = np.zeros((models, 3, 3))
        self.w = np.full(models, 1.0 / models)
        self.started = False
        # One identity per hypothesis, copied rather than rebuilt on every step.
        self._eye = np.tile(_I3, (models, 1, 1))

    def start(self, vn: float, ve: float, vel_std: float) -> None:
        """Spread the hypotheses round the circle, all starting at the GPS velocity."""
        self.x[:, 0], self.x[:, 1] = vn, ve
        self.x[:, 2] = np.arange(self.n) * math.tau / self.n - math.pi
        spread = math.pi / self.n  # half the gap between neighbours
        self.P[:] = np.diag([vel_std**2, vel_std**2, spread**2])
        self.w[:] = 1.0 / self.n
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
        yaw = self.x[:, 2]
        cy, sy = np.cos(yaw), np.sin(yaw)
        a_n = cy * f_fwd - sy * f_right
        a_e = sy * f_fwd + cy * f_right
        self.x[:, 0] += a_n * dt
        self.x[:, 1] += a_e * dt
        self.x[:, 2] = np.remainder(yaw + yaw_rate * dt + math.pi, math.tau) - math.pi
        phi = self._eye.copy()
        phi[:, 0, 2] = -a_e * dt
        phi[:, 1, 2] = a_n * dt
        self.P = phi @ self.P @ phi.transpose(0, 2, 1) + _Q_PER_S * dt

    def update(self, vn: float, ve: float, vel_std: float) -> None:
        """Correct every hypothesis with a GPS velocity and re-weigh them by its likelihood."""
        if not (math.isfinite(vn) and math.isfinite(ve)):
            return
        if not self.started:
            self.start(vn, ve, vel_std)
            return
        var = vel_std**2
        r = np.array([[var, 0.0], [0.0, var]])
        y = np.array([vn, ve]) - self.x[:, :2]
        s = self.P[:, :2, :2] + r
        s_inv = np.linalg.inv(s)
        nis = np.einsum("ni,nij,nj->n", y, s_inv, y)
        likelihood = np.exp(-0.5 * np.minimum(nis, MAX_NIS)) / (
            math.tau * np.sqrt(np.linalg.det(s))
        )
        k = self.P[:, :, :2] @ s_inv  # (n, 3, 2)
        self.x += np.einsum("nij,nj->ni", k, y)
        self.x[:, 2] = np.remainder(self.x[:, 2] + math.pi, math.tau) - math.pi
        ikh = self._eye.copy()  # I - K·H, H picking vn and ve: K's columns subtracted
        ikh[:, :, :2] -= k
        self.P = ikh @ self.P @ ikh.transpose(0, 2, 1) + k @ r @ k.transpose(0, 2, 1)
        w = self.w * likelihood
        total = float(w.sum())
        if total > 0.0 and math.isfinite(total):
            self.w = np.maximum(w / total, MIN_WEIGHT)
            self.w /= self.w.sum()

    def heading(self) -> tuple[float, float] | None:
        """(yaw, 1-σ) in radians, or None before the first GPS velocity."""
        if not self.started:
            return None
        yaw = self.x[:, 2]
        mean = math.atan2(float(self.w @ np.sin(yaw)), float(self.w @ np.cos(yaw)))
        off = np.remainder(yaw - mean + math.pi, math.tau) - math.pi
        var = float(self.w @ (off**2 + self.P[:, 2, 2]))
        return mean, math.sqrt(var)
