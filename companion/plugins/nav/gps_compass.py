"""``nav.gps_compass``: the thesis's final configuration as a plug-in.

Reads GPS fixes and compass readings, feeds them in time order to the navigator in
``companion.navigation.gps_compass``, and publishes ``nav/state`` at the compass rate (and
on each fix). The same navigator runs in ``companion replay``.
"""

from __future__ import annotations

from companion.messages import Compass, GpsFix
from companion.navigation.gps_compass import GpsCompassNavigator
from companion.plugin import FLIGHT_NICE, Plugin, PluginContext

WAIT_S = 0.5


class GpsCompassPlugin(Plugin):
    """GPS for position and velocity, the compass for attitude."""

    nice = FLIGHT_NICE

    inputs = ("sensors/gps", "sensors/compass")
    outputs = ("nav/state",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.nav = GpsCompassNavigator()
        self.gps = ctx.bus.queue_reader("sensors/gps")
        self.compass = ctx.bus.queue_reader("sensors/compass")
        self.waiter = ctx.bus.waiter([self.gps, self.compass])
        self.out = ctx.bus.writer("nav/state")

    def step(self) -> None:
        self.waiter.sleep(WAIT_S)
        samples: list[GpsFix | Compass] = [*self.gps.drain(), *self.compass.drain()]
        if not samples:
            return
        for sample in sorted(samples, key=lambda s: s.t_us):
            if isinstance(sample, GpsFix):
                self.nav.on_gps(sample)
            else:
                self.nav.on_compass(sample)
            self.ctx.health.ok()
        self.ctx.health.frames_bad = self.nav.rejected
        self.out.publish(self.nav.state(max(s.t_us for s in samples)))

    def close(self) -> None:
        self.waiter.close()
