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
from typing import Any, Generic, TypeVar

from companion.plugin import Plugin, PluginContext, Setting
from companion.sensors.codec_types import Framer, SentenceDecoder
from companion.sensors.line_framer import LineFramer
from companion.sensors.serial_port import ReopeningSerial

ReadingT = TypeVar("ReadingT")


def serial_settings(example_url: str, baud: int) -> dict[str, Setting]:
    """The ``device`` and ``baud`` settings, with the device's usual URL and rate."""
    return {
        "device": Setting(str, doc=f"{example_url}, a pty path or a pyserial URL"),
        "baud": Setting(int, baud, "baud rate when the URL does not give one", min=300),
    }


class SerialSensor(Plugin, Generic[ReadingT]):
    """A sensor that sends text lines on a serial port (or pty, socket, loop)."""

    decoder: SentenceDecoder[ReadingT]

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.port = ReopeningSerial(
            ctx.settings["device"], ctx.settings["baud"], stop_fd=ctx.stop_fd
        )
        self.framer = self.make_framer()
        self.decoder = self.make_decoder(ctx.settings)

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
        with self.ctx.bus.idle:  # waiting for the device is not busy time
            data, t_us = self.port.read_stamped(self.ctx.clock.now_us)
        for sentence in self.framer.feed(data):
            reading = self.decoder.decode(sentence, t_us)
            if reading is not None:
                self.publish(reading, t_us)
        c = self.decoder.counters
        self.ctx.health.frames_ok = c.ok
        self.ctx.health.frames_bad = c.bad_checksum + c.garbage + self.framer.rejected

    def close(self) -> None:
        self.port.close()
