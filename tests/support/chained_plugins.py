"""Test plug-ins that declare a trigger, for the composed process's chain (run on the
wake-up of the plug-in that publishes their input), named as module:Class in configs."""

from __future__ import annotations

import ctypes
import threading
import time

from companion.messages import ActuatorCommand, Imu, NavState
from companion.plugin import Plugin, PluginContext, Setting
from tests.support.plugins import Ticker


class ThreadTicker(Ticker):
    """The pretend IMU, falling silent after ``count`` samples: each sample carries its
    count (``ax``) and the native id of the thread that published it (``gx``)."""

    settings = {
        **Ticker.settings,
        "count": Setting(int, 1_000_000, "samples before it falls silent", min=0),
        "wake_every": Setting(int, 1, "wake the readers on every n-th sample only", min=1),
    }

    def step(self) -> None:
        with self.ctx.bus.idle:
            self._pace.wait(self.period_s)
        if self.count >= self.ctx.settings["count"]:
            return
        self.count += 1
        sample = Imu(t_us=self.ctx.clock.now_us(), ax_m_s2=float(self.count))
        sample.gx_rad_s = float(threading.get_native_id())
        self.writer.publish(sample, self.count % self.ctx.settings["wake_every"] == 0)


class ChainedRelay(Plugin):
    """Each IMU sample as nav/state: ``roll`` its count, ``pitch`` the native id of the
    thread this step ran on, ``yaw`` the id of the thread that published the sample. A wait
    that ends with no sample publishes ``roll`` -1 (what a plug-in's own timeout does)."""

    trigger = "sensors/imu"
    inputs = ("sensors/imu",)
    outputs = ("nav/state",)
    settings = {"crash_at": Setting(int, 0, "raise on the sample with this count (0: never)")}

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.imu = ctx.bus.queue_reader("sensors/imu")
        self.nav = ctx.bus.writer("nav/state")

    def step(self) -> None:
        samples = self.imu.take(timeout_s=0.3)
        me = float(threading.get_native_id())
        if not samples:
            self.nav.publish(NavState(t_us=self.ctx.clock.now_us(), roll_rad=-1.0, pitch_rad=me))
        for sample in samples:
            if sample.ax_m_s2 == self.ctx.settings["crash_at"]:
                raise RuntimeError("deliberate crash on the producer's thread")
            out = NavState(t_us=sample.t_us, roll_rad=sample.ax_m_s2, pitch_rad=me)
            out.yaw_rad = sample.gx_rad_s
            self.nav.publish(out)
            self.ctx.health.ok()


class ChainedBurner(Plugin):
    """Chained to the relay's nav/state: burns ``burn_ms`` of CPU a state (a controller's
    work), and says so on control/actuators."""

    trigger = "nav/state"
    inputs = ("nav/state",)
    outputs = ("control/actuators",)
    settings = {"burn_ms": Setting(float, 2.0, "CPU burnt a state, ms", min=0.0)}

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.nav = ctx.bus.latest_reader("nav/state", keep=64)
        self.out = ctx.bus.writer("control/actuators")

    def step(self) -> None:
        self.nav.wait_event(0.05)  # within its trigger_timeout_s
        for state in self.nav.drain():
            end = time.thread_time() + self.ctx.settings["burn_ms"] / 1000
            while time.thread_time() < end:
                pass
            self.out.publish(ActuatorCommand(t_us=state.t_us))


class SlowInit(Plugin):
    """A plug-in whose init holds the interpreter's lock for ``hold_s`` (a C call that does
    not let it go, as a slow import or a driver's blocking call can): every other thread
    of its process stands still meanwhile."""

    settings = {"hold_s": Setting(float, 1.5, "seconds init holds the lock", min=0.0)}

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        # PyDLL calls keep the lock, unlike ctypes.CDLL's.
        ctypes.PyDLL(None).usleep(int(ctx.settings["hold_s"] * 1e6))

    def step(self) -> None:
        with self.ctx.bus.idle:
            time.sleep(0.1)
