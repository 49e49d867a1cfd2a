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
# Until the headings flown span this much, the wind along the heading is not observable
# (on a straight line airspeed and the along-heading wind are one unknown): only the
# crosswind is updated, or a take-off roll's acceleration would be taken for tailwind.
OBSERVABLE_TURN_RAD = math.pi / 2


class WindEstimator:
    """State [airspeed, wind north, wind east] (m/s)."""

    def __init__(self) -> None:
        self.x = np.zeros(3)
        self.p = np.diag([100.0, WIND_PRIOR**2, WIND_PRIOR**2])
        self.started = False
        self._unwrapped = 0.0  # heading since the start, unwrapped, rad
        self._span = (0.0, 0.0)  # least and most of it
        self._last_heading: float | None = None
        self.observable = False  # the headings flown have shown the whole wind

    @property
    def airspeed(self) -> float:
        """Estimated true airspeed, m/s."""
        return float(max(self.x[0], 0.0))

    @property
    def turned(self) -> float:
        """How wide a range of headings has been flown, rad."""
        return self._span[1] - self._span[0]

    @property
    def wind_ne(self) -> tuple[float, float]:
        """Estimated wind (the way it blows), m/s north and east."""
        return float(self.x[1]), float(self.x[2])

    def _hold_along_wind(self, c: float, s: float) -> None:
        """Give the wind along the heading no uncertainty, so no update moves it; when the
        headings flown first span enough to see it, it gets its prior uncertainty back."""
        if self.turned >= OBSERVABLE_TURN_RAD:
            self.observable = True
            self.p[1:, 1:] += np.eye(2) * WIND_PRIOR**2
            return
        t = np.eye(2) - np.outer((c, s), (c, s))
        self.p[1:, 1:] = t @ self.p[1:, 1:] @ t
        self.p[0, 1:] = self.p[0, 1:] @ t
        self.p[1:, 0] = t @ self.p[1:, 0]

    def on_ground(self, vel_ne: tuple[float, float], heading: float) -> None:
        """Rolling on wheels: no crab, so nothing to learn about the wind; airspeed is the
        ground speed along the heading less the (held) wind along it."""
        c, s = math.cos(heading), math.sin(heading)
        along = vel_ne[0] * c + vel_ne[1] * s
        self.x[0] = max(0.0, along - (self.x[1] * c + self.x[2] * s))
        self._last_heading = None  # turns on the ground say nothing about the wind
        self.started = True

    def update(self, vel_ne: tuple[float, float], heading: float, dt: float) -> None:
        """Fuse one ground velocity (m/s) with the heading (rad) it was flown on."""
        c, s = math.cos(heading), math.sin(heading)
        if self._last_heading is not None:
            self._unwrapped += math.remainder(heading - self._last_heading, math.tau)
            lo, hi = self._span
            self._span = (min(lo, self._unwrapped), max(hi, self._unwrapped))
        self._last_heading = heading
        if not self.started:
            self.x[0] = max(0.0, vel_ne[0] * c + vel_ne[1] * s)
            self.started = True
        self.p += np.diag([AIRSPEED_NOISE**2, WIND_NOISE**2, WIND_NOISE**2]) * max(dt, 0.0)
        if not self.observable:
            self._hold_along_wind(c, s)
        h = np.array([[c, 1.0, 0.0], [s, 0.0, 1.0]])
        innovation = np.asarray(vel_ne) - h @ self.x
        ph = self.p @ h.T
        gain = ph @ np.linalg.inv(h @ ph + np.eye(2) * VELOCITY_NOISE**2)
        self.x += gain @ innovation
        self.p = (np.eye(3) - gain @ h) @ self.p
        self.p = 0.5 * (self.p + self.p.T)
