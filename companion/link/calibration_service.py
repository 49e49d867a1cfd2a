"""The gyro and level calibrations a ground station starts, run on the IMU's own samples.

QGroundControl's Sensors page follows a calibration by PX4's status texts
(SensorsComponentController.cc, _handleUASTextMessage): "[cal] calibration started: 2
<kind>" (2: the text protocol's version), "[cal] progress <percent>", then "[cal]
calibration done: <kind>", "[cal] calibration failed: <why>" or "[cal] calibration
cancelled". Both calibrations here average ``WINDOW_S`` of the IMU's own time, the
aircraft standing still (its samples' spread judged as the navigator judges a standing
aircraft, ``companion.navigation.ins_still``):
- gyro: the mean rate is what the offsets missed. It is added to INS_GYROFFS_X/Y/Z (the
  IMU's axes, ``companion.sensors.imu_calibration``), which the IMU driver takes off every
  sample from then on; the navigator still estimates whatever bias is left;
- level: the tilt of the mean specific force is the mounting's tilt the trim missed, and
  AHRS_TRIM_X/Y become the two rotations together.
The results are written as a ground station's PARAM_SET is (every ground station gets the
new values; the IMU driver follows params/changes). The link reads every IMU sample only
while a calibration runs (``VehiclePort.open_imu``; its telemetry shows the newest alone).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from companion.link.codec import dialect as d
from companion.link.microservice import Outgoing, Peer
from companion.link.params_service import ParamsService
from companion.messages import Imu
from companion.navigation.ins_still import MAX_ACCEL_SPREAD, MAX_GRAVITY_ERROR, MAX_GYRO_SPREAD
from companion.params import ParamError
from companion.sensors.imu_calibration import (
    GYRO_OFFSETS,
    MAX_GYRO_OFFSET,
    MAX_TRIM_RAD,
    TRIMS,
    Vec3,
    mounting,
    multiply,
    roll_pitch,
    rotate,
    tilt,
    transpose,
)

if TYPE_CHECKING:  # the port's package imports this module's users
    from companion.link.commands.port import VehiclePort

WINDOW_S = 3.0  # of the IMU's time, averaged
NO_DATA_S = 3.0  # beyond the window without it filled: the IMU has gone quiet
MIN_SAMPLES = 20
GRAVITY = 9.80665
PREFIX = "[cal] "
RUN_PERIOD_S = 0.05  # a running calibration takes in its samples this often
INFO, CRITICAL = d.MAV_SEVERITY_INFO, d.MAV_SEVERITY_CRITICAL


class StillWindow:
    """Sums of the IMU's samples: their means, and whether the aircraft stood still."""

    def __init__(self) -> None:
        self.n = 0
        self.sums = [0.0] * 12  # accel, gyro, and their squares
        self.first_us: int | None = None
        self.last_us = 0

    def add(self, imu: Imu) -> None:
        values = (imu.ax_m_s2, imu.ay_m_s2, imu.az_m_s2, imu.gx_rad_s, imu.gy_rad_s, imu.gz_rad_s)
        if not all(math.isfinite(v) for v in values):
            return
        for i, v in enumerate(values):
            self.sums[i] += v
            self.sums[6 + i] += v * v
        self.n += 1
        self.first_us = imu.t_us if self.first_us is None else self.first_us
        self.last_us = imu.t_us

    @property
    def span_s(self) -> float:
        return 0.0 if self.first_us is None else (self.last_us - self.first_us) / 1e6

    def means(self) -> tuple[Vec3, Vec3] | str:
        """(mean specific force, mean rate), or why they are not a still aircraft's."""
        if self.n < MIN_SAMPLES:
            return f"{self.n} IMU samples in {WINDOW_S:g} s"
        mean = [s / self.n for s in self.sums[:6]]
        spread = [
            math.sqrt(max(q / self.n - m * m, 0.0))
            for q, m in zip(self.sums[6:], mean, strict=True)
        ]
        if max(spread[:3]) > MAX_ACCEL_SPREAD or max(spread[3:]) > MAX_GYRO_SPREAD:
            return "the aircraft moved, hold it still"
        if abs(math.hypot(*mean[:3]) - GRAVITY) > MAX_GRAVITY_ERROR:
            return "the IMU does not read 1 g"
        ax, ay, az, gx, gy, gz = mean
        return (ax, ay, az), (gx, gy, gz)


class Calibration:
    """One calibration at a time; a link service that handles no message, only ticks."""

    handles: frozenset[str] = frozenset()

    def __init__(self, port: VehiclePort, params: ParamsService) -> None:
        self.port = port
        self.params = params
        self.kind: str | None = None  # "gyro" or "level" while one runs
        self.window = StillWindow()
        self.samples: Any = None  # the IMU's samples (drain, close) while one runs
        self.started_us = 0
        self.progress = 0
        self._texts: list[tuple[str, int]] = []  # sent at the next tick: after the ack
        self._out: list[Outgoing] = []
        self._ticked_s = -math.inf

    @property
    def running(self) -> bool:
        return self.kind is not None

    def has_imu(self) -> bool:
        """Whether the config runs an IMU driver that keeps a calibration."""
        return all(name in self.params.store.decls for name in (*GYRO_OFFSETS, *TRIMS))

    def start(self, kind: str, now_us: int) -> None:
        self.kind, self.window, self.started_us, self.progress = kind, StillWindow(), now_us, 0
        self.samples = self.port.open_imu()
        self.say(f"calibration started: 2 {kind}")

    def _stop(self) -> None:
        self.kind = None
        if self.samples is not None:
            self.samples.close()
            self.samples = None

    def say(self, text: str, severity: int = INFO) -> None:
        self._texts.append((PREFIX + text, severity))

    def fail(self, why: str) -> None:
        self._stop()
        self.say(f"calibration failed: {why}", CRITICAL)

    def cancel(self) -> bool:
        """Stop the calibration under way (False: none was)."""
        if self.kind is None:
            return False
        self._stop()
        self.say("calibration cancelled", CRITICAL)
        return True

    def reset(self) -> None:
        """The calibration back to its defaults (a level mounting, no offsets): what PX4's
        PREFLIGHT_STORAGE "reset sensor calibration" does, sent at the next tick."""
        for name in (*GYRO_OFFSETS, *TRIMS):
            if name in self.params.store.decls:
                self._out += self.params.write(name, self.params.store.decls[name].default)

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        return []

    def next_due(self) -> float:
        """While a calibration runs, its samples are taken in and judged this often."""
        if self._out or self._texts:
            return 0.0
        return self._ticked_s + RUN_PERIOD_S if self.kind is not None else math.inf

    def tick(self, now_s: float) -> list[Outgoing]:
        self._ticked_s = now_s
        out, self._out = self._out, []
        out += self._run() if self.kind is not None else []
        for text, severity in self._texts:
            self.port.statustext(text, severity)
        self._texts.clear()
        return out

    def _run(self) -> list[Outgoing]:
        for imu in self.samples.drain():
            if imu.t_us >= self.started_us:  # the reader may hold a few from before
                self.window.add(imu)
        done = min(100, int(100 * self.window.span_s / WINDOW_S)) // 20 * 20
        if done > self.progress and done < 100:
            self.progress = done
            self.say(f"progress <{done}>")
        if self.window.span_s >= WINDOW_S:
            return self._finish()
        if (self.port.snapshot.now_us - self.started_us) / 1e6 > WINDOW_S + NO_DATA_S:
            self.fail(f"{self.window.n} IMU samples in {WINDOW_S + NO_DATA_S:g} s")
        return []

    def _finish(self) -> list[Outgoing]:
        kind, means = self.kind, self.window.means()
        if isinstance(means, str):
            self.fail(means)
            return []
        accel, rate = means
        updates = self._gyro(rate) if kind == "gyro" else self._level(accel)
        if isinstance(updates, str):
            self.fail(updates)
            return []
        out: list[Outgoing] = []
        try:
            for name, value in updates.items():
                out += self.params.write(name, value)
        except ParamError as exc:
            self.fail(str(exc))
            return out
        self._stop()
        self.say("progress <100>")
        self.say(f"calibration done: {kind}")
        return out

    def _now(self, name: str) -> float:
        return self.params.store.get(name)

    def _trim(self) -> tuple[float, float]:
        return self._now(TRIMS[0]), self._now(TRIMS[1])

    def _gyro(self, rate: Vec3) -> dict[str, float] | str:
        """The offsets in the IMU's axes: the samples' rate was turned into the airframe's."""
        missed = rotate(transpose(mounting(*self._trim())), *rate)
        new = {n: self._now(n) + r for n, r in zip(GYRO_OFFSETS, missed, strict=True)}
        if max(abs(v) for v in new.values()) > MAX_GYRO_OFFSET:
            return f"gyro offset over {MAX_GYRO_OFFSET:g} rad/s, is it turning?"
        return new

    def _level(self, accel: Vec3) -> dict[str, float] | str:
        missed = mounting(*tilt(accel))
        roll, pitch = roll_pitch(multiply(missed, mounting(*self._trim())))
        if max(abs(roll), abs(pitch)) > MAX_TRIM_RAD:
            tilted = math.degrees(max(abs(roll), abs(pitch)))
            return f"tilted {tilted:.1f} deg, level the aircraft"
        return {TRIMS[0]: roll, TRIMS[1]: pitch}
