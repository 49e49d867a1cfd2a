"""How long a driver may let its device's frames pile up before it reads them.

A driver that reads every frame as it comes wakes at the device's rate (100 Hz for a
TFmini, 70 Hz for an SBUS receiver), and on a small board a wake-up of a Python process
costs about as much as the work done in it (``benchmarks/wake_floor.py``). Where nothing
needs each frame at once (a rangefinder far above the ground, the receiver while the
autopilot flies), the driver reads what piled up once a batch instead: the same frames,
each stamped a device period apart (``spread_stamps``), for a fraction of the wake-ups.
Pure: vehicle and wall times in, a wait out.
"""

from __future__ import annotations

# Wall seconds a vehicle microsecond lasts at most: a simulation running slower than real
# time (held by a late process) must not stretch a batch past its length on the wall.
_REAL_TIME = 1e-6


class ReadPacer:
    """The wait before a device's next read, for batches of ``batch_s`` of vehicle time."""

    def __init__(self, batch_s: float) -> None:
        self.batch_us = round(batch_s * 1e6)
        self._last: tuple[int, float] | None = None  # (vehicle µs, wall s) of the last read
        self._wall_per_us = _REAL_TIME

    def read_at(self, vehicle_us: int, wall_s: float) -> None:
        """A read happened at ``vehicle_us`` (``wall_s`` on a monotonic wall clock)."""
        if self._last is not None:
            vehicle, wall = vehicle_us - self._last[0], wall_s - self._last[1]
            if vehicle > 0 and wall > 0:  # a simulation may run faster than the wall clock
                self._wall_per_us = min(wall / vehicle, _REAL_TIME)
        self._last = (vehicle_us, wall_s)

    def pause_s(self, vehicle_us: int) -> float:
        """Wall seconds to wait now so the next read comes a batch after the last one
        (0: read at once), at the pace vehicle time ran at between the last two reads."""
        if self.batch_us <= 0 or self._last is None:
            return 0.0
        return self.wall_s_until(self._last[0] + self.batch_us, vehicle_us)

    def wall_s_until(self, deadline_us: int, vehicle_us: int) -> float:
        """Wall seconds until vehicle time reaches ``deadline_us`` from ``vehicle_us`` (0 when
        past), at the pace vehicle time ran at between the last two reads."""
        return max(0.0, (deadline_us - vehicle_us) * self._wall_per_us)
