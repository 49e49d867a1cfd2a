"""``sensors.os3000``: the OS-3000/OS-5000 digital compass on a serial port."""

from __future__ import annotations

import math

from companion.plugin import Plugin, PluginContext, Setting
from companion.sensors.line_framer import LineFramer
from companion.sensors.os3000 import Os3000Decoder
from companion.sensors.serial_port import ReopeningSerial


class Os3000Compass(Plugin):
    """Publishes compass attitude, and magnetometer readings when the sentence has them."""

    settings = {
        "device": Setting(str, doc="serial:///dev/ttyS0:19200, a pty path or a pyserial URL"),
        "baud": Setting(int, 19200, "baud rate when the URL does not give one", min=300),
        "mag_unit_gauss": Setting(float, 1e-3, "gauss per unit of the Mx/My/Mz fields", min=0.0),
        "declination_deg": Setting(
            float,
            0.0,
            "magnetic declination, east positive: added to make heading true",
            min=-180.0,
            max=180.0,
        ),
    }
    outputs = ("sensors/compass", "sensors/mag")

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.port = ReopeningSerial(ctx.settings["device"], ctx.settings["baud"])
        self.framer = LineFramer()
        self.decoder = Os3000Decoder(ctx.settings["mag_unit_gauss"])
        self.compass = ctx.bus.writer("sensors/compass")
        self.mag = ctx.bus.writer("sensors/mag")
        self.declination_rad = math.radians(ctx.settings["declination_deg"])

    def step(self) -> None:
        with self.ctx.bus.idle:
            data, t_us = self.port.read_stamped(self.ctx.clock.now_us)
        for sentence in self.framer.feed(data):
            reading = self.decoder.decode(sentence, t_us)
            if reading is None:
                continue
            heading = reading.compass.heading_rad + self.declination_rad
            reading.compass.heading_rad = heading % math.tau
            self.compass.publish(reading.compass)
            if reading.mag is not None:
                self.mag.publish(reading.mag)
        c, f = self.decoder.counters, self.framer.counters
        self.ctx.health.frames_ok = c.ok
        self.ctx.health.frames_bad = c.bad_checksum + c.garbage + f.overlong + f.garbage_runs

    def close(self) -> None:
        self.port.close()
