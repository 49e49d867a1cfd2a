"""Run a navigator over recorded samples: what ``companion replay`` and the benchmarks do.

The navigators are the very classes the plug-ins run; this only feeds them in time order
and collects their solution at a fixed rate of log time.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator
from typing import Protocol

from companion.messages import Baro, Compass, GpsFix, Imu, Magnetometer, Message, NavState
from companion.navigation.gps_compass import GpsCompassNavigator
from companion.navigation.ins_ekf import InsEkf, InsEkfConfig
from companion.navigation.sample_order import PublishGrid, SampleOrder


class Navigator(Protocol):
    """What a navigator offers to an offline run."""

    def feed(self, sample: Message) -> None: ...

    def solution(self, t_us: int) -> NavState: ...


class InsEkfRunner:
    """``nav.ins_ekf``'s navigator."""

    def __init__(
        self, declination_deg: float | None = None, config: InsEkfConfig | None = None
    ) -> None:
        self.nav = InsEkf(config or InsEkfConfig(declination_deg=declination_deg))
        self._feed: dict[type, Callable[[Message], None]] = {
            Imu: self.nav.on_imu,  # type: ignore[dict-item]
            GpsFix: self.nav.on_gps,  # type: ignore[dict-item]
            Compass: self.nav.on_compass,  # type: ignore[dict-item]
            Magnetometer: self.nav.on_mag,  # type: ignore[dict-item]
            Baro: self.nav.on_baro,  # type: ignore[dict-item]
        }

    def feed(self, sample: Message) -> None:
        """Route one sample to the filter."""
        handler = self._feed.get(type(sample))
        if handler is not None:
            handler(sample)

    def solution(self, t_us: int) -> NavState:
        """The solution at the last IMU sample."""
        return self.nav.state()


class GpsCompassRunner:
    """``nav.gps_compass``'s navigator."""

    def __init__(self, declination_deg: float | None = None) -> None:
        self.nav = GpsCompassNavigator()

    def feed(self, sample: Message) -> None:
        """GPS fixes and compass readings; everything else is not used."""
        if isinstance(sample, GpsFix):
            self.nav.on_gps(sample)
        elif isinstance(sample, Compass):
            self.nav.on_compass(sample)

    def solution(self, t_us: int) -> NavState:
        """The solution predicted to ``t_us``."""
        return self.nav.state(t_us)


NAVIGATORS: dict[str, Callable[[float | None], Navigator]] = {
    "ins_ekf": InsEkfRunner,
    "gps_compass": GpsCompassRunner,
}


def true_headings(samples: Iterable[Message], declination_deg: float | None) -> Iterator[Message]:
    """Compass headings made true (logs keep them magnetic, as the compass reports them).
    None: left magnetic (the INS applies the World Magnetic Model's declination itself)."""
    offset = math.radians(declination_deg or 0.0)
    for sample in samples:
        if offset and isinstance(sample, Compass):
            sample.heading_rad = (sample.heading_rad + offset) % math.tau
        yield sample


def run_navigator(
    navigator: Navigator, samples: Iterable[Message], rate_hz: float = 50.0
) -> Iterator[NavState]:
    """Feed the samples (in time order) and yield the solution every 1/rate_hz of log time."""
    period_us = round(1e6 / rate_hz)
    next_us: int | None = None
    for sample in samples:
        navigator.feed(sample)
        t = int(sample.t_us)
        if next_us is None:
            next_us = t
        if t >= next_us:
            yield navigator.solution(t)
            next_us += period_us * max(1, (t - next_us) // period_us + 1)


def run_as_plugin(
    runner: InsEkfRunner, samples: Iterable[Message], rate_hz: float = 50.0
) -> Iterator[NavState]:
    """What ``nav.ins_ekf`` publishes given the samples in the order they reached it: the
    plug-in's own ordering buffer and publication grid, so a log of its inputs replays to
    its very states."""
    order, grid = SampleOrder(), PublishGrid(rate_hz)
    for sample in samples:
        for ready in order.push((sample,)):
            runner.feed(ready)
            if grid.due(runner.nav.t_us, ready):
                yield runner.nav.state()
