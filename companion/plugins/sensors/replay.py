"""``sensors.replay``: play a recorded sensor log onto the sensor channels.

Each sample keeps the log's time stamp (``t_us``), so the navigators downstream run as
they would have in the air. ``speed`` 1 plays in real time, N plays N times faster, 0 as
fast as the process can publish. The wait between samples stands in for a device read.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

from companion.messages import Message
from companion.navigation.offline import true_headings
from companion.plugin import FLIGHT_NICE, NO_VEHICLE, Plugin, PluginContext, Setting
from companion.sensors.sensorlog import CHANNEL_OF, LogStats, read_sensor_log


class ReplaySensors(Plugin):
    """Publishes a sensor log's samples on sensors/imu, gps, mag, baro and compass."""

    nice = FLIGHT_NICE

    settings = {
        "file": Setting(str, doc="sensor log CSV (the design's format)"),
        "speed": Setting(float, 1.0, "1 real time, N faster, 0 as fast as possible", min=0.0),
        "loop": Setting(bool, False, "start again at the end"),
        "declination_deg": Setting(
            float, 0.0, "added to the log's (magnetic) compass headings", min=-180, max=180
        ),
    }
    outputs = tuple(CHANNEL_OF.values())

    @classmethod
    def validate(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[str]:
        path = Path(settings["file"]).expanduser()
        return [] if path.is_file() else [f"sensor log {path} does not exist"]

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.path = Path(ctx.settings["file"]).expanduser()
        self.writers = {kind: ctx.bus.writer(name) for kind, name in CHANNEL_OF.items()}
        self._pace = threading.Event()
        if ctx.settings["speed"] != 1.0 and os.sched_getscheduler(0) != os.SCHED_OTHER:
            # Faster than real time is not real-time work: as a SCHED_FIFO thread a replay
            # as fast as it can go would hold a core (it keeps its nice value).
            os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
        self._restart()

    def _restart(self) -> None:
        self.stats = LogStats()
        self.samples: Iterator[Message] = true_headings(
            read_sensor_log(self.path, self.stats), self.ctx.settings["declination_deg"]
        )
        self.t0_log: int | None = None
        self.t0_wall = time.monotonic()

    def step(self) -> None:
        msg = next(self.samples, None)
        if msg is None:
            self.ctx.health.frames_bad = self.stats.bad
            if self.ctx.settings["loop"]:
                self._restart()
            else:
                with self.ctx.bus.idle:  # the log is over: wait quietly until stopped
                    self._pace.wait(0.5)
            return
        self._wait_until(msg.t_us)
        self.writers[type(msg)].publish(msg)
        self.ctx.health.ok()
        self.ctx.health.frames_bad = self.stats.bad

    def _wait_until(self, t_us: int) -> None:
        speed = self.ctx.settings["speed"]
        if self.t0_log is None:
            self.t0_log = t_us
        if speed <= 0:
            return
        due = self.t0_wall + (t_us - self.t0_log) / 1e6 / speed
        delay = due - time.monotonic()
        if delay > 0:
            with self.ctx.bus.idle:
                self._pace.wait(delay)
