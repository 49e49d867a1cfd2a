"""``sensors.nmea_gps``: an NMEA 0183 GPS on a serial port (or pty, socket, loop)."""

from __future__ import annotations

from companion.plugin import Plugin, PluginContext, Setting
from companion.sensors.line_framer import LineFramer
from companion.sensors.nmea_gps import NmeaGpsDecoder
from companion.sensors.serial_port import ReopeningSerial


class NmeaGps(Plugin):
    """Reads sentences, publishes one GpsFix per epoch on sensors/gps."""

    settings = {
        "device": Setting(str, doc="serial:///dev/ttyUSB0:4800, a pty path or a pyserial URL"),
        "baud": Setting(int, 4800, "baud rate when the URL does not give one", min=300),
    }
    outputs = ("sensors/gps",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.port = ReopeningSerial(ctx.settings["device"], ctx.settings["baud"])
        self.framer = LineFramer()
        self.decoder = NmeaGpsDecoder()
        self.out = ctx.bus.writer("sensors/gps")

    def step(self) -> None:
        with self.ctx.bus.idle:  # waiting for the device is not busy time
            data, t_us = self.port.read_stamped(self.ctx.clock.now_us)
        for sentence in self.framer.feed(data):
            fix = self.decoder.decode(sentence, t_us)
            if fix is not None:
                self.out.publish(fix)
        c = self.decoder.counters
        self.ctx.health.frames_ok = c.ok
        f = self.framer.counters
        self.ctx.health.frames_bad = c.bad_checksum + c.garbage + f.overlong + f.garbage_runs

    def close(self) -> None:
        self.port.close()
