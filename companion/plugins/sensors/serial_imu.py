"""``sensors.serial_imu``: a VectorNav VN-100/VN-200 in ASCII output mode.

VectorNav's ASCII protocol is public (the VN-100 user manual documents every register and
both checksums), is plain text a person can read on a terminal, and its ``$VNIMU`` and
``$VNYMR`` outputs carry accelerometer, gyro and magnetometer together; the sensor is common
on small UAVs. The codec is ``companion.sensors.vectornav``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from companion.messages import Baro
from companion.plugin import Plugin, PluginContext, Ports, Setting
from companion.sensors.barometer import pressure_altitude_m
from companion.sensors.line_framer import LineFramer
from companion.sensors.serial_port import ReopeningSerial
from companion.sensors.vectornav import VectorNavDecoder


class SerialImu(Plugin):
    """Publishes every IMU sample on sensors/imu, its magnetometer on sensors/mag and its
    pressure (as height above the first reading) on sensors/baro."""

    settings = {
        "device": Setting(str, doc="serial:///dev/ttyUSB1:115200, a pty path or a pyserial URL"),
        "baud": Setting(int, 115200, "baud rate when the URL does not give one", min=300),
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
        self.port = ReopeningSerial(ctx.settings["device"], ctx.settings["baud"])
        self.framer = LineFramer()
        self.decoder = VectorNavDecoder()
        self.imu = ctx.bus.writer("sensors/imu")
        self.mag = ctx.bus.writer("sensors/mag") if ctx.settings["publish_mag"] else None
        self.baro = ctx.bus.writer("sensors/baro") if ctx.settings["publish_baro"] else None
        self.baro_ref_m: float | None = None

    def step(self) -> None:
        with self.ctx.bus.idle:
            data, t_us = self.port.read_stamped(self.ctx.clock.now_us)
        for sentence in self.framer.feed(data):
            reading = self.decoder.decode(sentence, t_us)
            if reading is None:
                continue
            self.imu.publish(reading.imu)
            if self.mag is not None:
                self.mag.publish(reading.mag)
            if self.baro is not None:
                self._publish_baro(t_us, reading.pressure_pa)
        c, f = self.decoder.counters, self.framer.counters
        self.ctx.health.frames_ok = c.ok
        self.ctx.health.frames_bad = c.bad_checksum + c.garbage + f.overlong + f.garbage_runs

    def _publish_baro(self, t_us: int, pressure_pa: float) -> None:
        height = pressure_altitude_m(pressure_pa)
        if not math.isfinite(height):
            return  # $VNYMR has no pressure
        if self.baro_ref_m is None:
            self.baro_ref_m = height
        self.baro.publish(
            Baro(t_us=t_us, alt_rel_m=height - self.baro_ref_m, pressure_pa=pressure_pa)
        )  # type: ignore[union-attr]

    def close(self) -> None:
        self.port.close()
