"""What every serial sensor plug-in does: read, frame, decode, publish, count.

A subclass names its decoder (``make_decoder``) and what a reading becomes on the bus
(``publish``); the port, the framing (text lines unless ``make_framer`` says otherwise, as
a binary protocol does), the time stamp and the health counters are here, once.

The codecs' side of the contract (``Framer``, ``SentenceDecoder``) lives with the codecs,
in ``companion.sensors.codec_types``.
"""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Mapping
from typing import Any, ClassVar, Generic, TypeVar

from companion.messages import VehicleStatus
from companion.plugin import NO_VEHICLE, DeviceProbe, Plugin, PluginContext, Setting
from companion.plugins.sensors.read_batching import DeviceReads
from companion.sensors.codec_types import Framer, SentenceDecoder
from companion.sensors.framed_stream import FramedStream
from companion.sensors.line_framer import LineFramer
from companion.sensors.serial_port import ReopeningSerial

__all__ = ["Framer", "SentenceDecoder", "SerialSensor", "serial_settings"]

ReadingT = TypeVar("ReadingT")


def serial_settings(example_url: str, baud: int, rate_hz: float) -> dict[str, Setting]:
    """The ``device``, ``baud`` and ``rate_hz`` settings, with the device's usual URL, baud
    rate and output rate (readings a second: what ``companion check`` expects to hear)."""
    return {
        "device": Setting(str, doc=f"{example_url}, a pty path or a pyserial URL"),
        "baud": Setting(int, baud, "baud rate when the URL does not give one", min=300),
        "rate_hz": Setting(float, rate_hz, "readings a second the device sends", min=0.0),
    }


class SerialSensor(Plugin, Generic[ReadingT]):
    """A sensor that sends text lines on a serial port (or pty, socket, loop)."""

    decoder: SentenceDecoder[ReadingT]
    # One frame per sample, sent every 1/rate_hz (an IMU, not a GPS's several sentences a
    # fix): frames a late read finds together are stamped a period apart, not alike.
    periodic_frames: ClassVar[bool] = False
    # Its bytes start the flight path (the IMU's): the port's driver is asked to hand them
    # over at once (``serial_port.set_low_latency``), not in a USB adapter's lumps.
    low_latency: ClassVar[bool] = False

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.port = ReopeningSerial(
            ctx.settings["device"],
            ctx.settings["baud"],
            stop_fd=ctx.stop_fd,
            low_latency=self.low_latency,
        )
        self.framer = self.make_framer()
        self.decoder = self.make_decoder(ctx.settings)
        self.stream = FramedStream(self.framer, self.decoder)
        # A device whose plug-in has a ``batch_s`` setting is read in batches when it may be.
        self.reads = DeviceReads(ctx, self.port, self.per_frame)

    def per_frame(self, status: VehicleStatus) -> bool:
        """Whether the vehicle, in this ``status``, needs each frame as it comes (a plug-in
        with a ``batch_s`` setting says when it does not)."""
        return True

    @classmethod
    def probe(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[DeviceProbe]:
        """The device, heard through this plug-in's own framer and decoder."""
        sensor = cls()  # never started: only its framer and decoder are wanted
        framer = sensor.make_framer()
        stream = FramedStream(framer, sensor.make_decoder(settings))
        device, baud, rate_hz = settings["device"], settings["baud"], settings["rate_hz"]
        return [DeviceProbe(device, baud, stream, rate_hz, text=isinstance(framer, LineFramer))]

    def make_framer(self) -> Framer:
        """The device's framing: ``$``-sentences ending at CR or LF unless overridden."""
        return LineFramer()

    @abstractmethod
    def make_decoder(self, settings: Mapping[str, Any]) -> SentenceDecoder[ReadingT]:
        """The device's decoder, configured from the plug-in's settings."""

    @abstractmethod
    def publish(self, reading: ReadingT, t_us: int) -> None:
        """Put one decoded reading on the bus."""

    def step(self) -> None:
        data, t_us, since = self.reads.read()
        if self.periodic_frames:
            for reading, t in self.stream.feed_spaced(data, t_us, since, self.reads.period_us):
                self.publish(reading, t)
        else:
            for reading in self.stream.feed(data, t_us):
                self.publish(reading, t_us)
        self.reads.expect_rest(self.framer.rest_bytes())
        health = self.ctx.health
        health.frames_ok, health.frames_bad = self.stream.frames_ok, self.stream.frames_bad
        health.bytes_in = self.port.bytes_in

    def close(self) -> None:
        self.port.close()
