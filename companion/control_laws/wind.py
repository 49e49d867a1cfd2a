"""Airspeed and wind without an airspeed sensor, from GPS velocity and heading.

With no sideslip the air-relative velocity points where the nose points, so the ground
velocity is ``Va·[cos ψ, sin ψ] + W``: linear in the airspeed ``Va`` and the wind ``W``.
A three-state Kalman filter lets the airspeed change quickly and the wind slowly; on a
straight leg only the cross-track wind is observable, and each turn reveals the rest, as
with ArduPlane flying without an airspeed sensor.
"""

from __future__ import annotations

import math

import numpy as np

AIRSPEED_NOISE = 0.8  # m/s per √s: throttle and pitch change airspeed quickly
WIND_NOISE = 0.03  # m/s per √s: the wind drifts slowly
VELOCITY_NOISE = 0.5  # m/s, GPS velocity (1 σ) plus sideslip
WIND_PRIOR = 4.0  # m/s, 1 σ before anything is known


class WindEstimator:
    """State [airspeed, wind north, wind east] (m/s)."""

    def __init__(self) -> None:
        self.x = np.zeros(3)
        self.p = np.diag([100.0, WIND_PRIOR**2, WIND_PRIOR**2])
        self.started = False

    @property
    def airspeed(self) -> float:
        """Estimated true airspeed, m/s."""
        return float(max(self.x[0], 0.0))

    @property
    def wind_ne(self) -> tuple[float, float]:
        """Estimated wind (the way it blows), m/s north and east."""
        return float(self.x[1]), float(self.x[2])

    def update(self, vel_ne: tuple[float, float], heading: float, dt: float) -> None:
        """Fuse one ground velocity (m/s) with the heading (rad) it was flown on."""
        c, s = math.cos(heading), math.sin(heading)
        if not self.started:
            self.x[0] = max(0.0, vel_ne[0] * c + vel_ne[1] * s)
            self.started = True
        self.p += np.diag([AIRSPEED_NOISE**2, WIND_NOISE**2, WIND_NOISE**2]) * max(dt, 0.0)
        h = np.array([[c, 1.0, 0.0], [s, 0.0, 1.0]])
        innovation = np.asarray(vel_ne) - h @ self.x
        ph = self.p @ h.T
        gain = ph @ np.linalg.inv(h @ ph + np.eye(2) * VELOCITY_NOISE**2)
        self.x += gain @ innovation
        self.p = (np.eye(3) - gain @ h) @ self.p
        self.p = 0.5 * (self.p + self.p.T)
