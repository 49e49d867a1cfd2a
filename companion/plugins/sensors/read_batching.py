"""A driver's reads batched while the vehicle does not need each frame at once.

The plug-in says when it needs every frame (``per_frame``, from the commander's
``vehicle/status`` and what it knows of its own readings); otherwise it reads once every
``batch_s`` of vehicle time (``companion.sensors.read_pacing``). Without a commander on the
bus nothing is known of the flight, and every frame is read as it comes.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from companion.fd_wait import wait_readable
from companion.messages import VehicleStatus
from companion.plugin import PluginContext, Setting
from companion.sensors.framed_stream import spread_since
from companion.sensors.read_pacing import ReadPacer
from companion.sensors.serial_port import ReopeningSerial

BITS_PER_BYTE = 10  # start, eight data bits, stop: the fewest any device's framing takes
# A frame's rest due sooner than this is read as it comes: a USB adapter hands bytes over a
# millisecond apart at best, so a shorter wait saves no wake-up.
MIN_REST_WAIT_S = 0.001


def batch_setting(what: str, default_s: float = 0.1) -> Setting:
    """The ``batch_s`` setting of a driver that batches ``what``."""
    return Setting(
        float,
        default_s,
        f"{what}, read the frames that piled up every batch_s of vehicle time"
        " (0: each frame as it comes)",
        min=0.0,
        max=1.0,
    )


class BatchedReads:
    """Waits before a read while ``per_frame(status)`` says batching is allowed."""

    def __init__(self, ctx: PluginContext, per_frame: Callable[[VehicleStatus], bool]) -> None:
        self.clock, self.stop_fd = ctx.clock, ctx.stop_fd
        self.pacer = ReadPacer(ctx.settings["batch_s"])
        self.per_frame = per_frame
        self.status = ctx.bus.latest_reader("vehicle/status") if self.pacer.batch_us else None

    def wait(self) -> None:
        """Before a read: let the frames pile up for the rest of the batch, unless the
        vehicle wants them one by one now. A stop request ends the wait."""
        if self.status is None:
            return
        status = self.status.get()
        if status is None or self.per_frame(status):
            return
        pause = self.pacer.pause_s(self.clock.now_us())
        if pause > 0:
            wait_readable([] if self.stop_fd is None else [self.stop_fd], pause)

    def read_done(self, t_us: int) -> None:
        """A read happened at vehicle time ``t_us``."""
        if self.status is not None:
            self.pacer.read_at(t_us, time.monotonic())


class DeviceReads:
    """A sensor plug-in's reads of its port: batched while ``per_frame`` allows it (when the
    plug-in has a ``batch_s`` setting), each stamped when its first byte came, and the mark
    its frames' own stamps may not go before (``spread_since``)."""

    def __init__(
        self,
        ctx: PluginContext,
        port: ReopeningSerial,
        per_frame: Callable[[VehicleStatus], bool],
    ) -> None:
        self.ctx, self.port = ctx, port
        rate_hz = ctx.settings["rate_hz"]
        self.period_us = 1e6 / rate_hz if rate_hz > 0 else 0.0  # the device's frame period
        self.batching = BatchedReads(ctx, per_frame) if "batch_s" in ctx.settings else None
        self._last_read_us: int | None = None
        self._stop_fds = [] if ctx.stop_fd is None else [ctx.stop_fd]
        self._rest_wait_s = 0.0

    def expect_rest(self, rest_bytes: int) -> None:
        """After a read that ended inside a frame: the next read first waits for as long as
        the line takes to carry ``rest_bytes`` more at its baud rate, so that the frame's
        pieces (a USB adapter's, a millisecond apart) wake the plug-in three or four times,
        not once each. The frame is decoded when whole either way, so it is no later."""
        baud = self.port.baud
        wait_s = rest_bytes * BITS_PER_BYTE / baud if baud > 0 else 0.0
        # Whole milliseconds (a poll's), rounded down: woken a little early, the read then
        # takes the last piece as it comes rather than after the wait.
        self._rest_wait_s = math.floor(wait_s * 1000) / 1000 if wait_s >= MIN_REST_WAIT_S else 0.0

    def read(self) -> tuple[bytes, int, int | None]:
        """What came (after the batch's wait), when its first byte came, and the time no
        frame of it can be stamped before."""
        # Waiting for the device is not busy time: counted as the bus's idle time (one
        # call, not ``with bus.idle``'s two, at every read of a 100 Hz device).
        started = time.perf_counter()
        try:
            if self._rest_wait_s:  # a stop request ends it; the read then sees the request
                wait_readable(self._stop_fds, self._rest_wait_s)
                self._rest_wait_s = 0.0
            if self.batching is not None:
                self.batching.wait()
            data, t_us = self.port.read_stamped(self.ctx.clock.now_us)
        finally:
            self.ctx.bus.idle.add_since(started)
        since = spread_since(self._last_read_us, self.ctx.health.reported_us)
        if data:
            self._last_read_us = t_us
            if self.batching is not None:
                self.batching.read_done(t_us)
        return data, t_us, since
