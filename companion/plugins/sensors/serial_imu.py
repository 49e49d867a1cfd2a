"""``sensors.serial_imu``: a VectorNav VN-100/VN-200 in ASCII output mode.

VectorNav's ASCII protocol is public (the VN-100 user manual documents every register and
both checksums), is plain text a person can read on a terminal, and its ``$VNIMU`` and
``$VNYMR`` outputs carry accelerometer, gyro and magnetometer together; the sensor is common
on small UAVs. The codec is ``companion.sensors.vectornav``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from companion.messages import Baro
from companion.plugin import PluginContext, Ports, Setting
from companion.plugins.sensors.serial_sensor import SerialSensor, serial_settings
from companion.sensors.barometer import pressure_altitude_m
from companion.sensors.vectornav import VectorNavDecoder, VectorNavReading

if TYPE_CHECKING:
    from companion.bus.channels import Writer


class SerialImu(SerialSensor[VectorNavReading]):
    """Publishes every IMU sample on sensors/imu, its magnetometer on sensors/mag and its
    pressure (as height above the first reading) on sensors/baro."""

    settings = {
        **serial_settings("serial:///dev/ttyUSB1:115200", 115200),
        "publish_mag": Setting(bool, True, "also publish the magnetometer on sensors/mag"),
        "publish_baro": Setting(bool, True, "also publish $VNIMU's pressure on sensors/baro"),
    }

    @classmethod
    def ports(cls, settings: Mapping[str, Any]) -> Ports:
        """sensors/mag and sensors/baro only when they are published."""
        mag = ("sensors/mag",) if settings.get("publish_mag", True) else ()
        baro = ("sensors/baro",) if settings.get("publish_baro", True) else ()
        return Ports(outputs=("sensors/imu", *mag, *baro))

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.imu = ctx.bus.writer("sensors/imu")
        self.mag = ctx.bus.writer("sensors/mag") if ctx.settings["publish_mag"] else None
        self.baro = ctx.bus.writer("sensors/baro") if ctx.settings["publish_baro"] else None
        self.baro_ref_m: float | None = None

    def make_decoder(self, settings: Mapping[str, Any]) -> VectorNavDecoder:
        return VectorNavDecoder()

    def publish(self, reading: VectorNavReading, t_us: int) -> None:
        self.imu.publish(reading.imu)
        if self.mag is not None:
            self.mag.publish(reading.mag)
        if self.baro is not None:
            self._publish_baro(self.baro, t_us, reading.pressure_pa)

    def _publish_baro(self, baro: Writer[Baro], t_us: int, pressure_pa: float) -> None:
        height = pressure_altitude_m(pressure_pa)
        if not math.isfinite(height):
            return  # $VNYMR has no pressure
        if self.baro_ref_m is None:
            self.baro_ref_m = height
        baro.publish(Baro(t_us=t_us, alt_rel_m=height - self.baro_ref_m, pressure_pa=pressure_pa))
