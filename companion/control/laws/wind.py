"""Airspeed and wind without an airspeed sensor, from GPS velocity and heading.

With no sideslip the air-relative velocity points where the nose points, so the ground
velocity is ``Va·[cos ψ, sin ψ] + W``: linear in the airspeed ``Va`` and the wind ``W``.
A three-state Kalman filter lets the airspeed change quickly and the wind slowly; on a
straight leg only the cross-track wind is observable, and each turn reveals the rest, as
with ArduPlane flying without an airspeed sensor.
"""

from __future__ import annotations

import math

AIRSPEED_NOISE = 0.8  # m/s per √s: throttle and pitch change airspeed quickly
WIND_NOISE = 0.03  # m/s per √s: the wind drifts slowly
VELOCITY_NOISE = 0.5  # m/s, GPS velocity (1 σ) plus sideslip
WIND_PRIOR = 4.0  # m/s, 1 σ before anything is known
# Until the headings flown span this much, the wind along the heading is not observable
# (on a straight line airspeed and the along-heading wind are one unknown): only the
# crosswind is updated, or a take-off roll's acceleration would be taken for tailwind.
OBSERVABLE_TURN_RAD = math.pi / 2


class WindEstimator:
    """State [airspeed, wind north, wind east] (m/s).

    Written out in floats rather than numpy: at 50 Hz in the controller, numpy's small-array
    overhead made this filter a fifth of the control step.
    """

    def __init__(self) -> None:
        self.x = [0.0, 0.0, 0.0]
        self.p = [[100.0, 0.0, 0.0], [0.0, WIND_PRIOR**2, 0.0], [0.0, 0.0, WIND_PRIOR**2]]
        self.started = False
        self._unwrapped = 0.0  # heading since the start, unwrapped, rad
        self._span = (0.0, 0.0)  # least and most of it
        self._last_heading: float | None = None
        self.observable = False  # the headings flown have shown the whole wind

    @property
    def airspeed(self) -> float:
        """Estimated true airspeed, m/s."""
        return max(self.x[0], 0.0)

    @property
    def turned(self) -> float:
        """How wide a range of headings has been flown, rad."""
        return self._span[1] - self._span[0]

    @property
    def wind_ne(self) -> tuple[float, float]:
        """Estimated wind (the way it blows), m/s north and east."""
        return self.x[1], self.x[2]

    def _hold_along_wind(self, c: float, s: float) -> None:
        """Give the wind along the heading no uncertainty, so no update moves it; when the
        headings flown first span enough to see it, it gets its prior uncertainty back.

        The wind block is projected on the crosswind direction ``u = (-s, c)``: with
        ``T = u uᵀ``, ``P_ww ← T P_ww T`` and the airspeed-wind terms ``← P_aw T``.
        """
        p = self.p
        if self.turned >= OBSERVABLE_TURN_RAD:
            self.observable = True
            p[1][1] += WIND_PRIOR**2
            p[2][2] += WIND_PRIOR**2
            return
        un, ue = -s, c
        cross = un * un * p[1][1] + 2.0 * un * ue * p[1][2] + ue * ue * p[2][2]
        p[1][1], p[1][2], p[2][2] = cross * un * un, cross * un * ue, cross * ue * ue
        p[2][1] = p[1][2]
        airspeed_cross = p[0][1] * un + p[0][2] * ue
        p[0][1] = p[1][0] = airspeed_cross * un
        p[0][2] = p[2][0] = airspeed_cross * ue

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
        x, p = self.x, self.p
        if not self.started:
            x[0] = max(0.0, vel_ne[0] * c + vel_ne[1] * s)
            self.started = True
        dt = max(dt, 0.0)
        p[0][0] += AIRSPEED_NOISE**2 * dt
        p[1][1] += WIND_NOISE**2 * dt
        p[2][2] += WIND_NOISE**2 * dt
        if not self.observable:
            self._hold_along_wind(c, s)
        self._fuse(vel_ne, c, s)

    def _fuse(self, vel_ne: tuple[float, float], c: float, s: float) -> None:
        """The Kalman update with H = [[c, 1, 0], [s, 0, 1]] and R = σ² I."""
        x, p = self.x, self.p
        innovation = (vel_ne[0] - c * x[0] - x[1], vel_ne[1] - s * x[0] - x[2])
        # P Hᵀ, one row per state.
        ph = [(c * row[0] + row[1], s * row[0] + row[2]) for row in p]
        r = VELOCITY_NOISE**2
        s00 = c * ph[0][0] + ph[1][0] + r
        s01 = c * ph[0][1] + ph[1][1]
        s10 = s * ph[0][0] + ph[2][0]
        s11 = s * ph[0][1] + ph[2][1] + r
        det = s00 * s11 - s01 * s10
        i00, i01, i10, i11 = s11 / det, -s01 / det, -s10 / det, s00 / det
        gain = [(a * i00 + b * i10, a * i01 + b * i11) for a, b in ph]
        for i in range(3):
            x[i] += gain[i][0] * innovation[0] + gain[i][1] * innovation[1]
        # P - K (H P), with H P = (P Hᵀ)ᵀ for a symmetric P; then kept symmetric.
        new = [
            [p[i][j] - gain[i][0] * ph[j][0] - gain[i][1] * ph[j][1] for j in range(3)]
            for i in range(3)
        ]
        self.p = [[0.5 * (new[i][j] + new[j][i]) for j in range(3)] for i in range(3)]
