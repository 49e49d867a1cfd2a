"""``sensors.nmea_gps``: an NMEA 0183 GPS on a serial port (or pty, socket, loop).

An RTK receiver's corrections from the ground station (``link/gps_inject``, joined from
GPS_RTCM_DATA by the link) are written to the same port, each message whole, as
ArduPilot's and PX4's GPS drivers pass them on.
"""

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
    optional_inputs = ("link/gps_inject",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.out = ctx.bus.writer("sensors/gps")
        self.corrections = ctx.bus.queue_reader("link/gps_inject")

    def step(self) -> None:
        super().step()
        # Written at the next read of the receiver's own data (several a second): RTCM's
        # corrections are good for seconds, and the port is not to be waited on for them.
        for message in self.corrections.pending():
            self.port.write(message.payload())  # counted in the port's bytes_out

    def make_decoder(self, settings: Mapping[str, Any]) -> NmeaGpsDecoder:
        return NmeaGpsDecoder()

    def publish(self, reading: GpsFix, t_us: int) -> None:
        self.out.publish(reading)
