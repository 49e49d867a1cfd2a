"""``sensors.os3000``: the OS-3000/OS-5000 digital compass on a serial port.

Beside an IMU with its own magnetometer (a VectorNav's), the navigator fuses that one and
this heading only when it falls silent (``navigation.ins_ekf``): with ``batch_s`` set, the
compass is then read in batches, each frame still published with its own time, and read
frame by frame again as soon as no other magnetometer has spoken for ``MAG_SILENT_US``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from companion.messages import VehicleStatus
from companion.plugin import PluginContext, Setting
from companion.plugins.sensors.read_batching import batch_setting
from companion.plugins.sensors.serial_sensor import SerialSensor, serial_settings
from companion.sensors.os3000 import Os3000Decoder, Os3000Reading

# Another magnetometer silent for this long (vehicle time): the navigator may turn to this
# compass, which is then read frame by frame. Half a second: the navigator fuses a heading
# every 0.2 s at most, and takes the compass once the magnetometer is a second old.
MAG_SILENT_US = 500_000


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
        "batch_s": batch_setting(
            "While another magnetometer speaks on sensors/mag (the navigator fuses that one)", 0.0
        ),
    }
    optional_inputs = ("vehicle/status", "sensors/mag")
    outputs = ("sensors/compass", "sensors/mag")

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.compass = ctx.bus.writer("sensors/compass")
        self.mag = ctx.bus.writer("sensors/mag")
        self.declination_rad = math.radians(ctx.settings["declination_deg"])
        batched = ctx.settings["batch_s"] > 0
        self.other_mag = ctx.bus.newest_reader("sensors/mag") if batched else None
        self.own_mag = False  # this compass's sentences carry the field: it is the magnetometer

    def per_frame(self, status: VehicleStatus) -> bool:
        """Each frame as it comes unless another magnetometer spoke lately."""
        if self.other_mag is None or self.own_mag:
            return True
        mag = self.other_mag.get()
        return mag is None or self.ctx.clock.now_us() - mag.t_us > MAG_SILENT_US

    def make_decoder(self, settings: Mapping[str, Any]) -> Os3000Decoder:
        return Os3000Decoder(settings["mag_unit_gauss"])

    def publish(self, reading: Os3000Reading, t_us: int) -> None:
        heading = reading.compass.heading_rad + self.declination_rad
        reading.compass.heading_rad = heading % math.tau
        self.compass.publish(reading.compass)
        if reading.mag is not None:
            self.own_mag = True
            self.mag.publish(reading.mag)
