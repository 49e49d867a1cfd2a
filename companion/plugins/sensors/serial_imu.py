"""``sensors.serial_imu``: a VectorNav VN-100/VN-200 in ASCII output mode.

VectorNav's ASCII protocol is public (the VN-100 user manual documents every register and
both checksums), is plain text a person can read on a terminal, and its ``$VNIMU`` and
``$VNYMR`` outputs carry accelerometer, gyro and magnetometer together; the sensor is common
on small UAVs. The codec is ``companion.sensors.vectornav``. The plug-in owns the IMU's
calibration (``companion.sensors.imu_calibration``: gyro offsets and the mounting's tilt,
measured by MAV_CMD_PREFLIGHT_CALIBRATION) and publishes its samples corrected.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from companion.messages import Baro
from companion.params.live import LiveParams
from companion.plugin import FLIGHT_NICE, NO_VEHICLE, PluginContext, Ports, Setting
from companion.plugins.sensors.serial_sensor import SerialSensor, serial_settings
from companion.sensors.barometer import pressure_altitude_m
from companion.sensors.imu_calibration import IMU_CAL_PARAMS, ImuCalibration
from companion.sensors.line_framer import LineFramer
from companion.sensors.vectornav import VectorNavDecoder, VectorNavReading
from companion.time_grid import TimeGrid

if TYPE_CHECKING:
    from companion.bus.patterns import Writer

PARAMS_EVERY_US = 100_000  # a calibration's new values are looked for this often
# read_on_wake: the reader's wait ends this many bytes before the sentences it waits for
# are whole, at the least: a number in the next may be a digit or a sign shorter than in
# any of the last few, and woken that little early the reader takes the rest as it comes.
SENTENCE_SLACK = 8


class SerialImu(SerialSensor[VectorNavReading]):
    """Publishes every IMU sample on sensors/imu, its magnetometer on sensors/mag and its
    pressure (as height above the first reading) on sensors/baro."""

    periodic_frames = True
    low_latency = True

    nice = FLIGHT_NICE

    settings = {
        **serial_settings("serial:///dev/ttyUSB1:115200", 115200, 40.0),
        "publish_mag": Setting(bool, True, "also publish the magnetometer on sensors/mag"),
        "publish_baro": Setting(bool, True, "also publish $VNIMU's pressure on sensors/baro"),
        "aiding_hz": Setting(
            float,
            20.0,
            "publish the magnetometer and the pressure at most this often (vehicle time):"
            " the sensor sends them with every IMU sample, the navigator fuses a heading at"
            " most every 0.2 s and a height every 0.1 s (0: with every sample)",
            min=0.0,
            max=1000.0,
        ),
        "wake_hz": Setting(
            float,
            0.0,
            "wake the readers (the navigator) at this rate of vehicle time, on the grid the"
            " navigator publishes on: set it to the navigator's publish_hz; the samples"
            " between go with the next wake-up, every one of them (0: on every sample)",
            min=0.0,
            max=1000.0,
        ),
        "read_on_wake": Setting(
            bool,
            False,
            "with wake_hz: the driver itself sleeps until the sample that wakes the navigator"
            " has come, not at every sample (the port's driver holds the ones before it:"
            " termios VMIN), a wake-up a state; not in a lockstep simulation, which waits"
            " for every sample to be read",
        ),
    }

    params = IMU_CAL_PARAMS

    @classmethod
    def validate(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[str]:
        """read_on_wake needs the navigator's grid (wake_hz) and a device at least twice as
        fast (rate_hz): slower, every sample wakes the navigator anyway."""
        wake_hz, rate_hz = settings["wake_hz"], settings["rate_hz"]
        if settings.get("read_on_wake") and not (wake_hz > 0 and rate_hz >= 2 * wake_hz):
            return [
                f"read_on_wake needs wake_hz and an IMU at least twice as fast (rate_hz"
                f" {rate_hz:g}, wake_hz {wake_hz:g})"
            ]
        return []

    @classmethod
    def ports(cls, settings: Mapping[str, Any]) -> Ports:
        """sensors/mag and sensors/baro only when they are published."""
        mag = ("sensors/mag",) if settings.get("publish_mag", True) else ()
        baro = ("sensors/baro",) if settings.get("publish_baro", True) else ()
        return Ports(optional_inputs=("params/changes",), outputs=("sensors/imu", *mag, *baro))

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.imu = ctx.bus.writer("sensors/imu")
        self.mag = ctx.bus.writer("sensors/mag") if ctx.settings["publish_mag"] else None
        self.baro = ctx.bus.writer("sensors/baro") if ctx.settings["publish_baro"] else None
        self.baro_ref_m: float | None = None
        self.live = LiveParams(ctx.bus, self.params, Path(ctx.vehicle.get("state_dir", ".")))
        self._calibrate(self.live.values)
        self.params_due_us = 0
        wake_hz = ctx.settings["wake_hz"]
        self.wake_grid = TimeGrid(wake_hz) if wake_hz > 0 else None
        aiding_hz = ctx.settings["aiding_hz"]
        self.aiding_grid = TimeGrid(aiding_hz) if aiding_hz > 0 else None
        # read_on_wake: the sentences' framer (their lengths), the samples a navigation
        # period brought, and those since its end.
        framer = self.framer if isinstance(self.framer, LineFramer) else None
        self.line_framer = framer if ctx.settings["read_on_wake"] and wake_hz > 0 else None
        # At most the samples every period has: a period of 2.5 has 2 or 3, and a wait for
        # 3 would hold a state back by a sample where 2 made it.
        self.most_per_wake = int(ctx.settings["rate_hz"] / wake_hz + 1e-9) if wake_hz else 1
        self.period_samples = 0
        self.since_wake = 0

    def make_decoder(self, settings: Mapping[str, Any]) -> VectorNavDecoder:
        return VectorNavDecoder()

    def _calibrate(self, values: Mapping[str, float]) -> None:
        self.calibration = ImuCalibration.from_params(values)
        self.rotation = self.calibration.rotation
        self.identity = self.rotation is None and not any(self.calibration.gyro_offsets)

    def publish(self, reading: VectorNavReading, t_us: int) -> None:
        if t_us >= self.params_due_us:
            self.params_due_us = t_us + PARAMS_EVERY_US
            if self.live.poll():
                self._calibrate(self.live.values)
        if not self.identity:
            self.calibration.correct(reading.imu, reading.mag, self.rotation)
        # The sample that completes a navigation period wakes the navigator (and takes
        # the ones before it along): a wake-up costs the navigator its whole step.
        wake = self.wake_grid is None or self.wake_grid.passed(t_us)
        if wake:
            self.period_samples, self.since_wake = self.since_wake + 1, 0
        else:
            self.since_wake += 1
        # Its heading and height first: woken, the navigator finds them there. Not with
        # every sample: each one costs its readers (the navigator, the logger) a receive,
        # and the navigator would drop all but one in five of them.
        if self.aiding_grid is None or self.aiding_grid.passed(t_us):
            if self.mag is not None:
                self.mag.publish(reading.mag, wake)
            if self.baro is not None:
                self._publish_baro(self.baro, t_us, reading.pressure_pa, wake)
        self.imu.publish(reading.imu, wake)

    def step(self) -> None:
        bytes_before = self.port.bytes_in
        super().step()
        if self.line_framer is None:
            return
        if self.port.bytes_in == bytes_before:
            # A wait that ended with nothing read (a second's silence, a stop): what the
            # port may hold back under its count is taken at the next wait, as it is.
            self.port.wake_after(1)
            return
        # Sleep until the sample that completes the navigation period has come: as many as
        # the last period brought (the device's rate may not be the setting's), less those
        # already here.
        due = min(self.period_samples, self.most_per_wake) - self.since_wake
        self.port.wake_after(self.line_framer.bytes_until(due) - SENTENCE_SLACK)

    def _publish_baro(
        self, baro: Writer[Baro], t_us: int, pressure_pa: float, wake: bool = True
    ) -> None:
        height = pressure_altitude_m(pressure_pa)
        if not math.isfinite(height):
            return  # $VNYMR has no pressure
        if self.baro_ref_m is None:
            self.baro_ref_m = height
        baro.publish(
            Baro(t_us=t_us, alt_rel_m=height - self.baro_ref_m, pressure_pa=pressure_pa), wake
        )
