"""Puts samples from several sensor processes into the order a navigator must see them.

Each driver is its own process, so a GPS fix can reach the navigator before the IMU sample
of the same instant. The INS must be predicted to a time before an aiding measurement of
that time is fused, or the fix corrects the state of an earlier instant; and the result
would depend on which process the scheduler ran first. So aiding samples (GPS, heading,
barometer) wait until an IMU sample past their time has arrived: at equal times the IMU
sample goes first, and the aiding samples of one instant, whichever process delivered its
own first, are fed together in a fixed order of kinds (fusing a magnetometer before or after
a compass gives different numbers). A navigator whose IMU has gone quiet still gets its
aiding samples once newer ones have come ``max_hold_us`` later (sample times only: a
replayed log's times need not be the vehicle clock's).
"""

from __future__ import annotations

import heapq
from collections.abc import Sequence
from typing import Any

from companion.messages import Baro, Compass, GpsFix, Imu, Magnetometer
from companion.time_grid import TimeGrid

# Aiding samples of one instant are fed in this order (then any other kind), not as they came.
_KIND_RANK = {GpsFix: 0, Magnetometer: 1, Compass: 2, Baro: 3}

# The channels in the order ``nav.ins_ekf`` feeds aiding samples of one instant (the
# IMU first, then ``_KIND_RANK``); a replay breaks such ties the same way.
FEED_ORDER = ("sensors/imu", "sensors/gps", "sensors/mag", "sensors/compass", "sensors/baro")


class PublishGrid:
    """When the navigator publishes: after the first IMU sample at or past each tick of a
    fixed grid of vehicle time, whatever batches the samples came in."""

    def __init__(self, rate_hz: float) -> None:
        self.grid = TimeGrid(rate_hz)

    def due(self, t_us: int | None, sample: Any) -> bool:
        """Whether to publish after feeding ``sample`` (the navigator now at ``t_us``)."""
        return t_us is not None and isinstance(sample, Imu) and self.grid.passed(t_us)


class SampleOrder:
    """A time-ordering buffer in front of an IMU-driven navigator."""

    def __init__(self, max_hold_us: int = 200_000) -> None:
        self.max_hold_us = max_hold_us
        self.horizon_us: int | None = None  # the newest IMU time seen
        self.newest_us: int | None = None  # the newest time of any sample
        self._held: list[tuple[int, int, int, Any]] = []  # (time key, kind, arrival, sample)
        self._arrival = 0

    def push(self, samples: Sequence[Any]) -> list[Any]:
        """Take newly received samples; return those ready to feed, in feeding order."""
        if len(samples) == 1 and not self._held and isinstance(samples[0], Imu):
            return self._lone_imu(samples[0])
        for sample in samples:
            t = int(sample.t_us)
            is_imu = isinstance(sample, Imu)
            if is_imu and (self.horizon_us is None or t > self.horizon_us):
                self.horizon_us = t
            if self.newest_us is None or t > self.newest_us:
                self.newest_us = t
            self._arrival += 1
            # IMU before aiding at equal times, then the kind, then arrival: a total order.
            key = 2 * t + (0 if is_imu else 1)
            rank = -1 if is_imu else _KIND_RANK.get(type(sample), len(_KIND_RANK))
            heapq.heappush(self._held, (key, rank, self._arrival, sample))
        ready = []
        horizon = self.horizon_us if self.horizon_us is not None else -1
        stale_before = (self.newest_us or 0) - self.max_hold_us
        while self._held:
            key = self._held[0][0]
            # An IMU sample goes at the horizon; aiding samples only once it is past them,
            # when every sample of their instant is known to have come (lockstep) or late.
            if key > 2 * horizon and key // 2 > stale_before:
                break
            ready.append(heapq.heappop(self._held)[3])
        return ready

    def _lone_imu(self, sample: Imu) -> list[Any]:
        """What ``push`` gives for one IMU sample with nothing held: that sample, at once
        (it is the horizon, or behind it), without the heap's round trip, as at most IMU
        samples (aiding samples come a few times a second)."""
        t = int(sample.t_us)
        if self.horizon_us is None or t > self.horizon_us:
            self.horizon_us = t
        if self.newest_us is None or t > self.newest_us:
            self.newest_us = t
        self._arrival += 1
        return [sample]
