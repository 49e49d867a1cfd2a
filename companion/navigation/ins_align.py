"""Initial attitude for the INS, on the ground or already in the air.

- Roll and pitch: on the ground (ground speed under 2 m/s) from the mean specific force,
  which then points straight up. In the air the accelerometer cannot tell a coordinated
  turn from level flight (it reads no sideways force in either), so roll comes from the
  turn rate instead: tan φ = V ψ̇ / g, with ψ̇ from the gyros; pitch from the forward
  specific force as on the ground.
- Heading: the magnetometer levelled with that tilt, else the compass, else (in the air only,
  above 5 m/s) the GPS course, which ignores the wind's crab angle: it starts with a
  larger uncertainty and the heading updates correct it. In the air, a magnetometer heading
  far from the course (more than a crab angle) is a disturbed magnetometer: the course wins
  and the magnetometer starts out distrusted.
"""

from __future__ import annotations

import itertools
import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from companion.navigation.earth_field import EarthField
from companion.navigation.ins_mag import MagMonitor, mag_heading

STILL_SPEED_M_S = 2.0
COURSE_MIN_SPEED_M_S = 5.0
INTERFERED_STD = math.radians(30.0)
# In the air the turn-rate roll assumes a level, coordinated turn; a pull-up or a slip
# breaks it by tens of degrees, and the filter must be free to move that far.
AIR_TILT_STD = math.radians(15.0)


@dataclass(frozen=True)
class Alignment:
    """Initial attitude and how much to trust it (1-σ, radians)."""

    roll: float
    pitch: float
    yaw: float
    tilt_std: float
    yaw_std: float


class Aligner:
    """Collects a short window of IMU samples; ``align`` decides once a fix is known."""

    def __init__(self, window_s: float, gravity: float) -> None:
        self.window_us = window_s * 1e6
        self.samples: deque[tuple[int, np.ndarray, np.ndarray]] = deque()
        self.g = gravity

    def add_imu(self, t_us: int, accel: np.ndarray, gyro: np.ndarray) -> None:
        """One IMU sample; samples older than the window are forgotten."""
        self.samples.append((t_us, accel, gyro))
        while t_us - self.samples[0][0] > self.window_us:
            self.samples.popleft()

    def ready(self) -> bool:
        """The window is (nearly) full."""
        span = self.samples[-1][0] - self.samples[0][0] if self.samples else 0
        return len(self.samples) >= 2 and span >= 0.8 * self.window_us

    def tilt(self, ground_speed: float) -> tuple[float, float, float]:
        """(roll, pitch, 1-σ) from the window."""
        f = np.mean([s[1] for s in self.samples], axis=0)
        pitch = math.atan2(f[0], math.hypot(f[1], f[2]))
        if ground_speed < STILL_SPEED_M_S:
            return math.atan2(-f[1], -f[2]), pitch, math.radians(2.0)
        q, r = np.mean([s[2] for s in self.samples], axis=0)[1:3]
        roll = 0.0
        for _ in range(3):  # ψ̇ = (q sin φ + r cos φ) / cos θ, φ = atan(V ψ̇ / g)
            yaw_rate = (q * math.sin(roll) + r * math.cos(roll)) / math.cos(pitch)
            roll = math.atan(ground_speed * yaw_rate / self.g)
        # That is the roll of the window's middle; a rolling aircraft (real logs start
        # rolling at 2 rad/s) has rolled on since: the gyro says how far.
        rolled = self._rolled_since_middle()
        std = math.hypot(AIR_TILT_STD, 0.5 * rolled)
        return math.remainder(roll + rolled, math.tau), pitch, std

    def _rolled_since_middle(self) -> float:
        middle = 0.5 * (self.samples[0][0] + self.samples[-1][0])
        rolled = 0.0
        for (t0, _, g0), (t1, _, _) in itertools.pairwise(self.samples):
            if t0 >= middle:
                rolled += g0[0] * (t1 - t0) / 1e6
        return rolled

    def align(
        self,
        vel_ned: np.ndarray,
        compass_heading: float | None,
        mag_body: np.ndarray | None,
        field: EarthField,
        monitor: MagMonitor,
    ) -> Alignment | None:
        """The alignment, or None while a heading source is still missing."""
        if not self.ready():
            return None
        speed = math.hypot(vel_ned[0], vel_ned[1]) if np.all(np.isfinite(vel_ned[:2])) else 0.0
        roll, pitch, tilt_std = self.tilt(speed)
        course = math.atan2(vel_ned[1], vel_ned[0]) if speed > COURSE_MIN_SPEED_M_S else None
        if mag_body is not None:
            mag = mag_heading(mag_body, roll, pitch, field, 0.0, tilt_std)
            if monitor.heading_for_alignment(mag, course) and mag is not None:
                std = max(mag.std, 3 * tilt_std, INTERFERED_STD if mag.interfered else 0.0)
                return Alignment(roll, pitch, mag.heading, tilt_std, std)
        elif compass_heading is not None:
            return Alignment(roll, pitch, compass_heading, tilt_std, math.radians(15.0))
        if course is not None:
            return Alignment(roll, pitch, course, tilt_std, math.radians(20.0))
        return None
