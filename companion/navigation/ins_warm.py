"""Warm start: a navigator restarted in the air carries on from its last solution.

While the aircraft flies, the navigator writes its solution (position, velocity, attitude,
the IMU's biases, the GPS lag) to a small file in the state directory, five times a
second. A new process reads it back, and takes it up only when the sensors say the
aircraft is in the air: its first GPS fix moves faster than an aircraft on the ground (the
flight controller's landed speed), within a few seconds of the file by the vehicle's
clock, and near where the file's solution, carried on by its velocity, says it should be.
Then, instead of a cold alignment (half a second of IMU, then roll from the turn rate and
a heading from the magnetometer, a few degrees and metres off), it starts at once from
the last solution carried forward to now: position dead-reckoned over the gap (the fix's
when the two differ by more than MAX_MISS_M), velocity from GPS, the biases as they were.
The attitude is the file's turned by the gyros' rate now only over a short gap (a
navigator restarted alone, in about a second). Over a longer one (the whole vehicle
restarted) nobody knows how the aircraft turned: with the servos held as the dead
controller left them it may have rolled from one bank into the other, and the new
process's rate times the whole gap had been seen 40-100 degrees off, rolling the aircraft
over when the controller came back. Then the attitude is aligned in the air from what the
sensors say now (``ins_align``: roll from the turn rate, pitch from the specific force,
heading from the magnetometer, compass or course), with its own uncertainty, half a second
of IMU after the start. On the ground, with a stale file or one from elsewhere, the
alignment is cold.
"""

from __future__ import annotations

import json
import logging
import math
import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from companion.messages import GpsFix, NavState
from companion.messages.navigation import NAV_ATTITUDE_VALID
from companion.navigation import rotations as rot

if TYPE_CHECKING:
    from companion.navigation.ins_align import Alignment
    from companion.navigation.ins_config import InsEkfConfig
    from companion.navigation.local_frame import LocalFrame

log = logging.getLogger(__name__)

WARM_FILE = "nav_warm.json"
WRITE_PERIOD_US = 200_000  # 5 Hz of vehicle time: the file is at most this much behind
MAX_AGE_S = 10.0  # a supervisor restart under load takes a few seconds
# Over a gap this short the attitude is turned on by the gyros' rate now (a navigator
# restarted alone: about a second); over a longer one it is aligned in the air.
GYRO_GAP_S = 2.0
IN_AIR_SPEED_M_S = 8.0  # the flight controller's LANDED_SPEED: faster is flying
# The fix this far across from the solution dead-reckoned over the gap: the position is
# the fix's (a tight turn flown in the gap; under load, a simulator's fixes behind time);
# this far, the file is not this flight's.
MAX_MISS_M, OTHER_FLIGHT_M = 20.0, 1000.0
# How much the attitude may have changed over the gap, per second of it (and at once).
TILT_STD = (math.radians(2.0), math.radians(3.0))
YAW_STD = (math.radians(2.0), math.radians(3.0))


@dataclass(frozen=True)
class WarmState:
    """The solution as written (vehicle time, WGS-84, NED, body->NED quaternion)."""

    t_us: int
    lat_deg: float
    lon_deg: float
    alt_msl_m: float
    vel: tuple[float, float, float]
    q: tuple[float, float, float, float]
    accel_bias: tuple[float, float, float]
    gyro_bias: tuple[float, float, float]
    gps_lag_s: float


def warm_state(nav: NavState, gps_lag_s: float) -> WarmState | None:
    """The solution to write, or None: none yet (aligning), or not flying (only a restart
    in the air reads it, and a vehicle on the bench writes nothing to its state directory)."""
    flying = math.hypot(nav.vn_m_s, nav.ve_m_s) >= IN_AIR_SPEED_M_S
    if not flying or not nav.flags & NAV_ATTITUDE_VALID or not math.isfinite(nav.lat_deg):
        return None
    return WarmState(
        int(nav.t_us), nav.lat_deg, nav.lon_deg, nav.alt_msl_m,
        (nav.vn_m_s, nav.ve_m_s, nav.vd_m_s), tuple(nav.q), tuple(nav.accel_bias_m_s2),
        tuple(nav.gyro_bias_rad_s), gps_lag_s,
    )  # fmt: skip


class WarmFile:
    """The file in the state directory: written every WRITE_PERIOD_US, read once."""

    def __init__(self, state_dir: Path) -> None:
        self.path = state_dir / WARM_FILE
        self.next_us = 0
        self._fd: int | None = None
        self._size = 0  # the longest text written: a shorter one is padded over it
        self.failures = 0  # writes that failed (a full or read-only disk)

    def read(self) -> WarmState | None:
        """The last solution written, or None (none, or damaged: a cold start)."""
        try:
            raw = json.loads(self.path.read_text())
            state = WarmState(**raw)
            values = [state.t_us, state.lat_deg, state.lon_deg, state.alt_msl_m, *state.vel]
            values += [*state.q, *state.accel_bias, *state.gyro_bias, state.gps_lag_s]
            return state if len(values) == 18 and all(map(math.isfinite, values)) else None
        except (OSError, ValueError, TypeError):
            return None

    def due(self, t_us: int) -> bool:
        return t_us >= self.next_us

    def write(self, state: WarmState) -> None:
        """Overwrite the file in one write, padded with blanks (JSON ignores them) to the
        longest text written. A write to a temporary file and a rename cost ten times the
        CPU, five times a second; a killed process cannot leave one write half done (its
        bytes are in the page cache). No fsync: after a power cut a missing, old or torn
        file only means a cold start."""
        self.next_us = state.t_us + WRITE_PERIOD_US
        text = json.dumps(vars(state)).encode()
        self._size = max(self._size, len(text))
        try:
            if self._fd is None:  # this process's first write: an older file goes
                self.path.parent.mkdir(parents=True, exist_ok=True)
                self._fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            os.pwrite(self._fd, text.ljust(self._size), 0)
        except OSError as exc:  # a full or read-only disk must not stop the navigator
            # Said once: five times a second it buried every other line of the log.
            self.failures += 1
            level = logging.WARNING if self.failures == 1 else logging.DEBUG
            log.log(level, "warm start file not written (failure %d): %s", self.failures, exc)

    def close(self) -> None:
        """Let the file go (a plug-in restarted in its process opens it again)."""
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None


@dataclass(frozen=True)
class WarmSolution:
    """The navigator's state to start from: the last solution carried over the gap."""

    p: list[float]  # NED metres in the navigator's frame
    v: list[float]
    q: rot.Quat
    ba: list[float]  # the accelerometers' bias, m/s2
    bg: list[float]  # the gyros' bias, rad/s
    gps_lag_s: float
    P: np.ndarray  # the covariance, widened by the gap


def warm_start(
    frame: LocalFrame | None,
    cfg: InsEkfConfig,
    imu_window: Iterable[tuple[int, np.ndarray, np.ndarray]],
    warm: WarmState,
    fix: GpsFix,
    t_us: int,
    aligned: Alignment | None = None,
) -> WarmSolution | None:
    """``warm`` carried to ``t_us`` if the fix says it is this flight, in the air (None
    otherwise, and after a long gap while ``aligned``, the in-air alignment of now, is
    None: ``waits_for_alignment``); ``imu_window`` holds the (t_us, accel, gyro) samples
    read since the start."""
    age_s = (t_us - warm.t_us) / 1e6
    gps_vel = np.array((fix.vn_m_s, fix.ve_m_s, fix.vd_m_s))
    gps_vel = np.where(np.isfinite(gps_vel), gps_vel, warm.vel)
    speed = math.hypot(gps_vel[0], gps_vel[1])
    if frame is None or not 0.0 <= age_s <= MAX_AGE_S or speed < IN_AIR_SPEED_M_S:
        return None
    if age_s > GYRO_GAP_S and aligned is None:
        return None
    moved = 0.5 * (np.array(warm.vel) + gps_vel) * age_s
    p = frame.ned(warm.lat_deg, warm.lon_deg, warm.alt_msl_m) + moved
    fix_p = frame.ned(fix.lat_deg, fix.lon_deg, warm.alt_msl_m)  # only across is judged
    fix_p += gps_vel * (t_us - fix.t_us) / 1e6
    miss = math.hypot(*(fix_p[:2] - p[:2]))
    if miss > OTHER_FLIGHT_M:
        log.info("warm start refused: the fix is %.0f m from the last solution", miss)
        return None
    if miss > MAX_MISS_M:  # the gap was flown otherwise than its ends' velocities say
        p[:2] = fix_p[:2]
    if age_s <= GYRO_GAP_S:
        q = _turned_over_the_gap([gyro for _t, _a, gyro in imu_window], warm, age_s)
        tilt_std, yaw_std = (s0 + s1 * age_s for s0, s1 in (TILT_STD, YAW_STD))
    else:
        assert aligned is not None
        q = rot.euler_to_quaternion(aligned.roll, aligned.pitch, aligned.yaw)
        tilt_std, yaw_std = aligned.tilt_std, aligned.yaw_std
    pos_std = 2.0 + 0.5 * age_s
    diag = [pos_std] * 3 + [max(cfg.gps_vel_std, 0.5)] * 3 + [tilt_std, tilt_std, yaw_std]
    diag += [0.5 * cfg.accel_bias_std] * 3 + [0.5 * cfg.gyro_bias_std] * 3
    how = "turned by the gyros" if age_s <= GYRO_GAP_S else "aligned in the air"
    log.info("warm start: %.1f s after the last solution written, attitude %s", age_s, how)
    return WarmSolution(
        p.tolist(), gps_vel.tolist(), q,
        list(warm.accel_bias), list(warm.gyro_bias), warm.gps_lag_s, np.diag(np.square(diag)),
    )  # fmt: skip


def waits_for_alignment(warm: WarmState, t_us: int) -> bool:
    """Whether a warm start at ``t_us`` needs the in-air alignment, which is not there yet
    (a long gap, but not too long for the file)."""
    return GYRO_GAP_S < (t_us - warm.t_us) / 1e6 <= MAX_AGE_S


def _turned_over_the_gap(gyro_rates: list[np.ndarray], warm: WarmState, age_s: float) -> rot.Quat:
    """The file's attitude turned by the gyros' rate since this process started, over the
    whole (short) gap: a rolling or turning aircraft has rolled and turned on meanwhile (in
    lockstep, rolling at 17 deg/s, the roll as written was 5 deg off 0.3 s later)."""
    if not gyro_rates:
        return tuple(warm.q)  # type: ignore[return-value]
    w = np.mean(gyro_rates, axis=0) - np.array(warm.gyro_bias)
    turn = rot.rotation_vector_quaternion(*(float(x) * age_s for x in w))
    return rot.normalized(rot.multiply(tuple(warm.q), turn))  # type: ignore[arg-type]
