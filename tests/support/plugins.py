"""Small plug-ins that exercise the runtime, named in test configs as module:Class.

They stand in for devices the way a third-party plug-in would: not registered, found by
``"tests.support.plugins:ClassName"``.
"""

from __future__ import annotations

import threading

from companion.messages import ControlStatus, GpsFix, Imu, NavFlags, NavState
from companion.plugin import Plugin, PluginContext, Setting


class Ticker(Plugin):
    """A pretend IMU: one sample every 1/rate_hz seconds on sensors/imu, counting up."""

    settings = {"rate_hz": Setting(float, 50.0, "samples per second", min=0.1, max=10000)}
    outputs = ("sensors/imu",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.writer = ctx.bus.writer("sensors/imu")
        self.period_s = 1.0 / ctx.settings["rate_hz"]
        self.count = 0
        self._pace = threading.Event()  # stands in for a device's read timing

    def step(self) -> None:
        with self.ctx.bus.idle:  # pacing stands in for a device read: not busy time
            self._pace.wait(self.period_s)
        self.count += 1
        self.writer.publish(Imu(t_us=self.ctx.clock.now_us(), ax_m_s2=float(self.count)))
        self.ctx.health.ok()


class Relay(Plugin):
    """Turns every IMU sample into a nav/state value (roll_rad = the sample's ax)."""

    inputs = ("sensors/imu",)
    outputs = ("nav/state",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.imu = ctx.bus.queue_reader("sensors/imu")
        self.nav = ctx.bus.writer("nav/state")

    def step(self) -> None:
        for sample in self.imu.take(timeout_s=0.5):
            self.nav.publish(NavState(t_us=sample.t_us, roll_rad=sample.ax_m_s2))
            self.ctx.health.ok()


class Waiting(Plugin):
    """Waits on a channel nobody writes: its CPU use is the cost of an idle wait."""

    optional_inputs = ("sensors/mag",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.mag = ctx.bus.queue_reader("sensors/mag")

    def step(self) -> None:
        self.mag.take(timeout_s=0.5)


class CrashAfter(Plugin):
    """Raises after a number of steps (each step waits 10 ms)."""

    settings = {"steps": Setting(int, 5, "steps before the crash", min=0)}

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.left = ctx.settings["steps"]

    def step(self) -> None:
        if self.left <= 0:
            raise RuntimeError("deliberate crash for the restart test")
        self.left -= 1
        threading.Event().wait(0.01)


class FakeNav(Plugin):
    """A navigator stand-in: a known, valid solution on nav/state at 20 Hz."""

    settings = {"aligning": Setting(bool, False, "say ALIGNING, as a navigator starting up")}
    outputs = ("nav/state",)
    ROLL, PITCH, YAW = 0.1, -0.05, 1.2
    LAT, LON, ALT = -37.9105, 145.1340, 120.0

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.nav = ctx.bus.writer("nav/state")
        self._pace = threading.Event()

    def step(self) -> None:
        with self.ctx.bus.idle:
            self._pace.wait(0.05)
        msg = NavState(t_us=self.ctx.clock.now_us())
        msg.roll_rad, msg.pitch_rad, msg.yaw_rad = self.ROLL, self.PITCH, self.YAW
        msg.lat_deg, msg.lon_deg, msg.alt_msl_m = self.LAT, self.LON, self.ALT
        msg.vn_m_s, msg.ve_m_s, msg.vd_m_s = 20.0, 5.0, -1.0
        msg.q[0] = 1.0
        msg.flags = int(
            NavFlags.ATTITUDE_VALID
            | NavFlags.HEADING_VALID
            | NavFlags.POSITION_VALID
            | NavFlags.VELOCITY_VALID
        )
        if self.ctx.settings["aligning"]:
            msg.flags = int(NavFlags.ALIGNING)
        self.nav.publish(msg)


class FakeGps(Plugin):
    """A GPS stand-in: a fix at FakeNav's position five times a second (``fix_type`` 3: 3-D)."""

    settings = {"fix_type": Setting(int, 3, "GPS_FIX_TYPE of every fix", min=0, max=6)}
    outputs = ("sensors/gps",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.gps = ctx.bus.writer("sensors/gps")
        self._pace = threading.Event()

    def step(self) -> None:
        with self.ctx.bus.idle:
            self._pace.wait(0.2)
        fix = GpsFix(t_us=self.ctx.clock.now_us(), fix_type=self.ctx.settings["fix_type"])
        fix.lat_deg, fix.lon_deg, fix.alt_msl_m = FakeNav.LAT, FakeNav.LON, FakeNav.ALT
        fix.eph_m, fix.epv_m, fix.satellites = 1.2, 2.0, 9
        self.gps.publish(fix)
        self.ctx.health.ok()


class PublishOnce(Plugin):
    """Publishes one nav/state value at start and nothing after, as a rare event would."""

    outputs = ("nav/state",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.nav = ctx.bus.writer("nav/state")
        self.nav.publish(NavState(t_us=ctx.clock.now_us(), yaw_rad=0.25))
        self._pace = threading.Event()

    def step(self) -> None:
        with self.ctx.bus.idle:
            self._pace.wait(0.1)


class Burst(Plugin):
    """A pretend IMU that sends ``size`` numbered samples at once, ``bursts`` times, 0.5 s
    apart, then nothing: more than a reader's queue holds, so a slower reader loses some."""

    settings = {
        "size": Setting(int, 1000, "samples in one burst", min=1),
        "bursts": Setting(int, 3, "bursts before it falls silent", min=0),
    }
    outputs = ("sensors/imu",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.writer = ctx.bus.writer("sensors/imu")
        self.count = 0
        self.left = ctx.settings["bursts"]
        self._pace = threading.Event()

    def step(self) -> None:
        with self.ctx.bus.idle:
            self._pace.wait(0.5)
        # Not before a reader listens: a reader whose channel was being opened by this
        # process at the same time can take seconds to join, and would miss every burst.
        if self.left <= 0 or self.writer.readers() == 0:
            return
        self.left -= 1
        for _ in range(self.ctx.settings["size"]):
            self.count += 1
            # Microseconds apart, so the gap a loss leaves is as long as it is in samples.
            self.writer.publish(Imu(t_us=self.ctx.clock.now_us(), ax_m_s2=float(self.count)))
        self.ctx.health.ok()


class FakeApproach(Plugin):
    """A flight controller stand-in on a landing approach: its status ten times a second,
    in the air, LandPhase APPROACH (1)."""

    outputs = ("control/status",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.status = ctx.bus.writer("control/status")
        self._pace = threading.Event()

    def step(self) -> None:
        with self.ctx.bus.idle:
            self._pace.wait(0.1)
        self.status.publish(ControlStatus(t_us=self.ctx.clock.now_us(), landed=0, land_phase=1))
        self.ctx.health.ok()
