"""Standing still on the ground: the gyros then measure their own bias (a zero angular rate
update, the INS habit known as ZARU).

On the ground before take-off the aircraft does not turn, so what the gyros read, averaged
over a second, is their bias: far better than what the filter can learn in flight, where a
magnetometer disturbed by the motors' currents for seconds at a time would otherwise pull
the yaw-rate bias about (and with it the heading, for minutes). In the air, even a steady
hover is not still: the attitude controller keeps the airframe rocking by degrees per second,
and an aircraft that is moving is not on the ground; both are told apart by the spread of
the samples and the GPS speed.
"""

from __future__ import annotations

import math

import numpy as np

# Spread of single samples within the window: a grounded airframe, even with idling
# propellers, stays under these; a hovering multicopter is several times above.
MAX_GYRO_SPREAD = math.radians(1.5)  # rad/s
MAX_ACCEL_SPREAD = 0.3  # m/s²
MAX_GRAVITY_ERROR = 0.3  # m/s²: |mean specific force| against g
MAX_GROUND_SPEED = 0.5  # m/s, from GPS
# A turn slower than this could hide in a still window; it is allowed for in the noise.
UNSEEN_RATE = math.radians(0.02)  # rad/s


class StillDetector:
    """Collects IMU samples in windows; ``add`` returns the gyro mean and its variance when a
    window has closed and the aircraft was standing still in it."""

    def __init__(self, window_s: float, gravity: float = 9.80665) -> None:
        self.window_us = window_s * 1e6
        self.g = gravity
        self.start_us: int | None = None
        self.n = 0
        # Plain floats: this runs on every IMU sample, where numpy's per-call cost dominates.
        self.sums = [0.0] * 12  # accel, gyro, and their squares

    def add(
        self, t_us: int, accel: tuple[float, ...], gyro: tuple[float, ...], ground_speed: float
    ) -> tuple[np.ndarray, float] | None:
        """One raw IMU sample and the latest GPS ground speed (NaN when unknown)."""
        if self.start_us is None:
            self.start_us = t_us
        a0, a1, a2 = accel
        w0, w1, w2 = gyro
        s = self.sums  # written out: a loop over six values costs more than the sums
        s[0], s[1], s[2] = s[0] + a0, s[1] + a1, s[2] + a2
        s[3], s[4], s[5] = s[3] + w0, s[4] + w1, s[5] + w2
        s[6], s[7], s[8] = s[6] + a0 * a0, s[7] + a1 * a1, s[8] + a2 * a2
        s[9], s[10], s[11] = s[9] + w0 * w0, s[10] + w1 * w1, s[11] + w2 * w2
        self.n += 1
        if t_us - self.start_us < self.window_us:
            return None
        result = self._verdict(ground_speed)
        self.start_us, self.n = t_us, 0
        self.sums = [0.0] * 12
        return result

    def _verdict(self, ground_speed: float) -> tuple[np.ndarray, float] | None:
        if self.n < 5 or not ground_speed < MAX_GROUND_SPEED:  # NaN: not known still
            return None
        sums = np.array(self.sums)
        mean = sums[:6] / self.n
        spread = np.sqrt(np.maximum(sums[6:] / self.n - mean * mean, 0.0))
        if spread[:3].max() > MAX_ACCEL_SPREAD or spread[3:].max() > MAX_GYRO_SPREAD:
            return None
        if abs(float(np.linalg.norm(mean[:3])) - self.g) > MAX_GRAVITY_ERROR:
            return None
        variance = float(spread[3:].max() ** 2 / self.n + UNSEEN_RATE**2)
        return mean[3:], variance  # the same variance serves each axis
