"""Puts samples from several sensor processes into the order a navigator must see them.

Each driver is its own process, so a GPS fix can reach the navigator before the IMU sample
of the same instant. The INS must be predicted to a time before an aiding measurement of
that time is fused, or the fix corrects the state of an earlier instant; and the result
would depend on which process the scheduler ran first. So aiding samples (GPS, heading,
barometer) wait until an IMU sample at or past their time has arrived; at equal times the
IMU sample goes first. A navigator whose IMU has gone quiet still gets its aiding samples once
newer ones have come ``max_hold_us`` later (sample times only: a replayed log's times
need not be the vehicle clock's).
"""

from __future__ import annotations

import heapq
from collections.abc import Iterable
from typing import Any

from companion.messages import Imu

# The order ``nav.ins_ekf`` drains its inputs in, which is the arrival order of aiding
# samples of equal time read in one batch; a replay breaks such ties the same way.
FEED_ORDER = ("sensors/imu", "sensors/gps", "sensors/mag", "sensors/compass", "sensors/baro")


class PublishGrid:
    """When the navigator publishes: after the first IMU sample at or past each tick of a
    fixed grid of vehicle time, whatever batches the samples came in."""

    def __init__(self, rate_hz: float) -> None:
        self.period_us = round(1e6 / rate_hz)
        self.next_us = 0

    def due(self, t_us: int | None, sample: Any) -> bool:
        """Whether to publish after feeding ``sample`` (the navigator now at ``t_us``)."""
        if t_us is None or not isinstance(sample, Imu) or t_us < self.next_us:
            return False
        self.next_us = (t_us // self.period_us + 1) * self.period_us
        return True


class SampleOrder:
    """A time-ordering buffer in front of an IMU-driven navigator."""

    def __init__(self, max_hold_us: int = 200_000) -> None:
        self.max_hold_us = max_hold_us
        self.horizon_us: int | None = None  # the newest IMU time seen
        self.newest_us: int | None = None  # the newest time of any sample
        self._held: list[tuple[int, int, Any]] = []  # (t_us, arrival, sample)
        self._arrival = 0

    def push(self, samples: Iterable[Any]) -> list[Any]:
        """Take newly received samples; return those ready to feed, in feeding order."""
        for sample in samples:
            t = int(sample.t_us)
            is_imu = isinstance(sample, Imu)
            if is_imu and (self.horizon_us is None or t > self.horizon_us):
                self.horizon_us = t
            if self.newest_us is None or t > self.newest_us:
                self.newest_us = t
            self._arrival += 1
            # IMU before aiding at equal times, then arrival order: a total order.
            heapq.heappush(self._held, (2 * t + (0 if is_imu else 1), self._arrival, sample))
        ready = []
        horizon = self.horizon_us if self.horizon_us is not None else -1
        stale_before = (self.newest_us or 0) - self.max_hold_us
        while self._held:
            key, _, sample = self._held[0]
            t = key // 2
            if t > horizon and t > stale_before:
                break
            ready.append(heapq.heappop(self._held)[2])
        return ready
