"""``sensors.serial_imu``: a VectorNav VN-100/VN-200 in ASCII output mode.

VectorNav's ASCII protocol is public (the VN-100 user manual documents every register and
both checksums), is plain text a person can read on a terminal, and its ``$VNIMU`` and
``$VNYMR`` outputs carry accelerometer, gyro and magnetometer together; the sensor is common
on small UAVs. The codec is ``companion.devices.vectornav``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from companion.devices.line_framer import LineFramer
from companion.devices.serial_port import ReopeningSerial
from companion.devices.vectornav import VectorNavDecoder
from companion.plugin import Plugin, PluginContext, Ports, Setting


class SerialImu(Plugin):
    """Publishes every IMU sample on sensors/imu and its magnetometer on sensors/mag."""

    settings = {
        "device": Setting(str, doc="serial:///dev/ttyUSB1:115200, a pty path or a pyserial URL"),
        "baud": Setting(int, 115200, "baud rate when the URL does not give one", min=300),
        "publish_mag": Setting(bool, True, "also publish the magnetometer on sensors/mag"),
    }

    @classmethod
    def ports(cls, settings: Mapping[str, Any]) -> Ports:
        """sensors/mag only when the magnetometer is published."""
        mag = ("sensors/mag",) if settings.get("publish_mag", True) else ()
        return Ports(outputs=("sensors/imu", *mag))

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.port = ReopeningSerial(ctx.settings["device"], ctx.settings["baud"])
        self.framer = LineFramer()
        self.decoder = VectorNavDecoder()
        self.imu = ctx.bus.writer("sensors/imu")
        self.mag = ctx.bus.writer("sensors/mag") if ctx.settings["publish_mag"] else None

    def step(self) -> None:
        with self.ctx.bus.idle:
            data = self.port.read()
        t_us = self.ctx.clock.now_us()
        for sentence in self.framer.feed(data):
            reading = self.decoder.decode(sentence, t_us)
            if reading is None:
                continue
            self.imu.publish(reading.imu)
            if self.mag is not None:
                self.mag.publish(reading.mag)
        c, f = self.decoder.counters, self.framer.counters
        self.ctx.health.frames_ok = c.ok
        self.ctx.health.frames_bad = c.bad_checksum + c.garbage + f.overlong + f.garbage_runs

    def close(self) -> None:
        self.port.close()
