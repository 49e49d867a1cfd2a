"""How noisy the IMU's samples really are, measured from the samples themselves.

A datasheet's noise density holds for an averaged, well-mounted sensor. A logged IMU is
often a point sample at 10-25 Hz of a vibrating airframe: vibration aliases into it, and
between two samples the motion itself changes more than the filter, which holds each sample
over the interval, can follow. Half the mean square of the difference between consecutive
samples measures both; as a density (σ²·dt) it is the process noise the filter must allow
on velocity. The gyro is left at its configured density: its sample differences are mostly
the airframe's real angular acceleration, which the attitude integration follows well, and
counting them as noise would let every heading reading shake the yaw.
"""

from __future__ import annotations

import math


class ImuNoise:
    """Running sample-to-sample noise of the accelerometer, as a density."""

    def __init__(self, window_s: float, accel_floor: float, gyro_floor: float) -> None:
        self.window_s = window_s
        self.accel_floor, self.gyro_floor = accel_floor, gyro_floor
        self.accel_var = 0.0  # per sample, per axis
        self.dt = 0.0
        self.last: tuple[float, ...] | None = None

    def add(self, values: tuple[float, ...], dt: float) -> None:
        """One sample (ax, ay, az, gx, gy, gz), ``dt`` after the previous one."""
        last, self.last = self.last, values
        if last is None or dt <= 0.0:
            return
        # Written out: a generator's per-item cost shows at 100-400 Hz (same sum, same order).
        a = ((values[0] - last[0]) ** 2 + (values[1] - last[1]) ** 2
             + (values[2] - last[2]) ** 2) / 6.0  # fmt: skip
        w = min(1.0, dt / self.window_s)
        self.accel_var += w * (a - self.accel_var)
        self.dt += w * (dt - self.dt)

    def densities(self) -> tuple[float, float]:
        """(accelerometer, gyro) noise densities: the accelerometer's measured, never below
        its floor; the gyro's as configured."""
        return (
            max(self.accel_floor, math.sqrt(self.accel_var * self.dt)),
            self.gyro_floor,
        )
