"""``nav.ins_ekf``: the strapdown INS with its error-state EKF as a plug-in.

Reads the IMU, GPS and whichever heading sources exist (magnetometer, compass), feeds
them in time order to ``companion.navigation.ins_ekf.InsEkf`` (the navigator
``companion replay --navigator ins_ekf`` runs), and publishes ``nav/state`` at
``publish_hz`` of vehicle time.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Protocol

from companion.messages import Message
from companion.navigation.ins_ekf import InsEkfConfig
from companion.navigation.ins_warm import WarmFile, warm_state
from companion.navigation.offline import InsEkfRunner
from companion.navigation.sample_order import FEED_ORDER, PublishGrid, SampleOrder
from companion.plugin import FLIGHT_NICE, Plugin, PluginContext, Setting

WAIT_S = 1.0  # without an IMU: its status, and any aiding samples, once a second
_DEFAULTS = InsEkfConfig()


class InsEkfPlugin(Plugin):
    """IMU-driven navigation aided by GPS and a heading."""

    nice = FLIGHT_NICE
    trigger = "sensors/imu"
    trigger_timeout_s = WAIT_S

    settings = {
        "publish_hz": Setting(float, 50.0, "nav/state rate, in vehicle time", min=1.0, max=400),
        "declination_deg": Setting(
            float,
            math.nan,
            "magnetic declination (east +); nan: the World Magnetic Model's",
            min=-180,
            max=180,
        ),
        "gps_delay_s": Setting(
            float,
            math.nan,
            "how much the GPS's fixes lag the IMU; nan: measured in flight",
            min=0,
            max=1,
        ),
        "accel_noise": Setting(
            float, _DEFAULTS.accel_noise, "accelerometer noise density, m/s²/√Hz", min=1e-5
        ),
        "gyro_noise": Setting(
            float, _DEFAULTS.gyro_noise, "gyro noise density, rad/s/√Hz", min=1e-6
        ),
    }
    inputs = ("sensors/imu", "sensors/gps")
    optional_inputs = ("sensors/mag", "sensors/compass", "sensors/baro")
    outputs = ("nav/state",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        s = ctx.settings
        config = dataclasses.replace(
            _DEFAULTS,
            declination_deg=_given(s["declination_deg"]),
            gps_delay_s=_given(s["gps_delay_s"]),
            accel_noise=s["accel_noise"],
            gyro_noise=s["gyro_noise"],
        )
        self.runner = InsEkfRunner(config=config)
        self.readers = [ctx.bus.queue_reader(c) for c in FEED_ORDER]
        # Woken by the IMU only: an aiding sample waits for the IMU sample after it anyway
        # (SampleOrder), and without an IMU there is nothing to publish (``WAIT_S`` still
        # feeds it the aiding samples then).
        self.waiter = ctx.bus.waiter(self.readers[:1])
        self.out = ctx.bus.writer("nav/state")
        self.grid = PublishGrid(s["publish_hz"])
        self.order = SampleOrder()
        # The last solution, for a restart in the air (the state directory as configured).
        self.warm_file = WarmFile(Path(ctx.vehicle.get("state_dir", ".")))
        self.runner.nav.warm = self.warm_file.read()

    def step(self) -> None:
        self.waiter.sleep(WAIT_S)  # the waiter counts its own idle time; every reader is read
        samples = self.order.push(received(self.readers))
        if not samples:
            return
        nav = self.runner.nav
        for sample in samples:
            self.runner.feed(sample)
            # A lockstep simulation sees the same states at the same times every run.
            if self.grid.due(nav.t_us, sample):
                state = nav.state()
                self.out.publish(state)
                if self.warm_file.due(state.t_us) and (warm := warm_state(state, nav.lag.lag_s)):
                    self.warm_file.write(warm)
        self.ctx.health.ok(len(samples))
        self.ctx.health.frames_bad = nav.gps_rejected + nav.heading_rejected

    def close(self) -> None:
        self.waiter.close()
        self.warm_file.close()


class _Drains(Protocol):
    def pending(self) -> list[Message]: ...

    def has_samples(self) -> bool: ...


def received(readers: Sequence[_Drains]) -> list[Message]:
    """Every sample the readers hold: the IMU's (the first reader) taken before the others.

    In exact lockstep every aiding sample of a frame is on the bus before the simulator
    writes the next frame's IMU sample. Aiding readers drained after the IMU's therefore
    give every aiding sample older than the newest IMU sample taken, and ``SampleOrder``
    feeds each one before the IMU sample that follows it. Asked before (which readers had
    data when the wait ended), a fix or a heading published between that look and the
    IMU's drain stayed behind while the next frame's IMU sample was taken: it was fused one
    IMU step late or on time, as the threads happened to be scheduled. A thread of a composed
    process, sharing one interpreter, is held there for milliseconds, and its flight
    parted from the same flight in separate processes (issue 46.4).

    An aiding reader is asked whether it holds a sample (iceoryx2's own call) before it is
    drained: most hold none at most IMU samples, and an empty drain costs more.
    """
    imu, *aiding = readers
    taken = imu.pending()
    for reader in aiding:
        if reader.has_samples():
            taken += reader.pending()
    return taken


def _given(value: float) -> float | None:
    return None if math.isnan(value) else value
