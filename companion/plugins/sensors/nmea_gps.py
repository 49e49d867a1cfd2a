"""``sensors.nmea_gps``: an NMEA 0183 GPS on a serial port (or pty, socket, loop)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from companion.messages import GpsFix
from companion.plugin import PluginContext
from companion.plugins.sensors.serial_sensor import SerialSensor, serial_settings
from companion.sensors.nmea_gps import NmeaGpsDecoder


class NmeaGps(SerialSensor[GpsFix]):
    """Reads sentences, publishes one GpsFix per epoch on sensors/gps."""

    settings = serial_settings("serial:///dev/ttyUSB0:4800", 4800, 1.0)
    outputs = ("sensors/gps",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.out = ctx.bus.writer("sensors/gps")

    def make_decoder(self, settings: Mapping[str, Any]) -> NmeaGpsDecoder:
        return NmeaGpsDecoder()

    def publish(self, reading: GpsFix, t_us: int) -> None:
        self.out.publish(reading)
