"""GPS aiding for the INS: how late the fixes are, and the state they are compared with.

A receiver's fix describes the vehicle some time before the autopilot stamps it (the
receiver's own processing, the serial link, a 5 Hz navigation rate): 0.1-0.25 s on the
logs we have. Compared with the current state, a fix that lags 0.2 s at 20 m/s is 4 m and,
in a turn, 1 m/s wrong, and the filter would bend attitude and biases to explain it. So the
fix is compared with the INS's own state of that earlier time (kept for ``HISTORY_S``).

The lag need not be configured: ``GpsLag`` measures it. GPS velocity is a delayed copy of
the INS velocity (which the IMU makes in real time); the delay is the shift that makes the
two agree best, and every change of velocity (a turn, a climb, a speed change) shows it.
The sum of squared differences is kept for a grid of candidate lags, with a forgetting
time of ``window_s``, and the best candidate is used once enough change has been seen.
"""

from __future__ import annotations

import math
from collections import deque
from itertools import chain

import numpy as np

HISTORY_S = 1.0
LAG_STEP_S = 0.02
MAX_LAG_S = 0.5
# The velocity must have changed by this much (m/s, summed over the window) before a lag
# is believed: straight and level, every candidate fits as well as any other.
MIN_EXCITATION_M_S = 20.0
MIN_FIXES = 20
SWITCH_MARGIN = 0.05
MIN_CONTRAST = 1.5  # worst candidate's cost over the best's


class StateHistory:
    """The INS's position and velocity over the last second, for lagging fixes."""

    def __init__(self) -> None:
        self.rows: deque[tuple[int, list[float], list[float]]] = deque()

    def add(self, t_us: int, p: list[float], v: list[float]) -> None:
        """Remember the state at ``t_us`` (lists are kept, not copied: never mutated)."""
        self.rows.append((t_us, p, v))
        if self.rows[0][0] < t_us - HISTORY_S * 1e6:
            self.rows.popleft()

    def at(self, t_us: float) -> tuple[np.ndarray, np.ndarray] | None:
        """Position and velocity at ``t_us``, interpolated; None outside the history."""
        rows = self.rows
        if not rows or t_us > rows[-1][0] or t_us < rows[0][0]:
            return None
        for i in range(len(rows) - 1, 0, -1):
            t0, p0, v0 = rows[i - 1]
            t1, p1, v1 = rows[i]
            if t0 <= t_us <= t1:
                w = (t_us - t0) / (t1 - t0) if t1 > t0 else 1.0
                u = 1 - w
                # Floats, then one array each: the same products and sums as numpy's
                # elementwise ones, without five numpy calls on lists of three.
                p = [a * u + b * w for a, b in zip(p0, p1, strict=True)]
                v = [a * u + b * w for a, b in zip(v0, v1, strict=True)]
                return np.array(p), np.array(v)
        _, first_p, first_v = rows[0]
        return np.array(first_p), np.array(first_v)

    def velocities(self) -> tuple[np.ndarray, np.ndarray]:
        """Times (µs) and velocities (N×3) of the history, as arrays."""
        rows = self.rows
        n = len(rows)
        if not n:
            return np.zeros(0), np.zeros((0, 3))
        # fromiter over the floats: np.array over a hundred lists of three cost ~170 µs.
        ts = np.fromiter((r[0] for r in rows), float, n)
        vs = np.fromiter(chain.from_iterable(r[2] for r in rows), float, 3 * n)
        return ts, vs.reshape(n, 3)


class GpsLag:
    """Measures how late the GPS fixes are, from their velocity."""

    def __init__(self, window_s: float, initial_s: float) -> None:
        self.window_s = window_s
        self.lags = np.arange(0.0, MAX_LAG_S + 1e-9, LAG_STEP_S)
        self.lags_us = self.lags * 1e6
        self.cost = np.zeros(len(self.lags))
        self.excitation = 0.0
        self.fixes = 0
        self.lag_s = initial_s
        self.last: tuple[int, np.ndarray] | None = None

    def observe(self, t_us: int, v_gps: np.ndarray, history: StateHistory) -> None:
        """One fix's horizontal velocity against the INS history."""
        if not (math.isfinite(v_gps[0]) and math.isfinite(v_gps[1])):
            return
        ts, vs = history.velocities()
        when = t_us - self.lags_us
        if len(ts) < 2 or when[-1] < ts[0]:
            return
        vn = np.interp(when, ts, vs[:, 0])
        ve = np.interp(when, ts, vs[:, 1])
        err = np.square(v_gps[0] - vn) + np.square(v_gps[1] - ve)
        dt = (t_us - self.last[0]) / 1e6 if self.last is not None else 0.0
        forget = math.exp(-max(dt, 0.0) / self.window_s)
        if self.last is not None:
            change = float(np.linalg.norm(v_gps[:2] - self.last[1]))
            self.excitation = self.excitation * forget + change
        self.cost = self.cost * forget + err
        self.fixes += 1
        self.last = (t_us, v_gps[:2].copy())
        if self.fixes < MIN_FIXES or self.excitation < MIN_EXCITATION_M_S:
            return
        # The candidates must have been told apart: noise alone leaves the cost flat.
        if self.cost.max() < MIN_CONTRAST * self.cost.min():
            return
        best = int(np.argmin(self.cost))
        current = int(np.argmin(np.abs(self.lags - self.lag_s)))
        # Only a clearly better fit moves the lag: GPS noise alone makes neighbouring
        # candidates differ by a percent or two, and a wandering lag costs accuracy.
        if self.cost[best] < (1.0 - SWITCH_MARGIN) * self.cost[current]:
            self.lag_s = float(self.lags[best])
