"""The vehicle time base: monotonic microseconds on hardware, simulation time in SITL."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from companion.bus.patterns import LatestReader
    from companion.messages import SimClock


class VehicleClock(Protocol):
    """Where ``t_us`` stamps come from."""

    def now_us(self) -> int:
        """The current vehicle time in microseconds."""
        ...


class MonotonicClock:
    """Hardware time base: CLOCK_MONOTONIC in microseconds."""

    def now_us(self) -> int:
        """Monotonic time in microseconds."""
        return time.monotonic_ns() // 1000


class SimulationClock:
    """SITL time base: the newest ``sim/clock`` value the simulator published.

    Before the simulator has published anything the time is 0.
    """

    def __init__(self, reader: LatestReader[SimClock]) -> None:
        self._reader = reader

    def now_us(self) -> int:
        """Simulation time in microseconds."""
        latest = self._reader.get()
        return 0 if latest is None else int(latest.t_us)
