"""``sensors.os3000``: the OS-3000/OS-5000 digital compass on a serial port."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from companion.plugin import PluginContext, Setting
from companion.plugins.sensors.serial_sensor import SerialSensor, serial_settings
from companion.sensors.os3000 import Os3000Decoder, Os3000Reading


class Os3000Compass(SerialSensor[Os3000Reading]):
    """Publishes compass attitude, and magnetometer readings when the sentence has them."""

    periodic_frames = True

    settings = {
        **serial_settings("serial:///dev/ttyS0:19200", 19200, 20.0),
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
        self.compass = ctx.bus.writer("sensors/compass")
        self.mag = ctx.bus.writer("sensors/mag")
        self.declination_rad = math.radians(ctx.settings["declination_deg"])

    def make_decoder(self, settings: Mapping[str, Any]) -> Os3000Decoder:
        return Os3000Decoder(settings["mag_unit_gauss"])

    def publish(self, reading: Os3000Reading, t_us: int) -> None:
        heading = reading.compass.heading_rad + self.declination_rad
        reading.compass.heading_rad = heading % math.tau
        self.compass.publish(reading.compass)
        if reading.mag is not None:
            self.mag.publish(reading.mag)
