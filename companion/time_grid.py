"""A fixed grid of vehicle time, and the first sample at or past each of its ticks.

The navigator publishes on one (``nav.ins_ekf``'s ``publish_hz``) and the IMU driver may
wake its readers on the same one (``sensors.serial_imu``'s ``wake_hz``): the samples that
complete a navigation period are then exactly the ones that wake the navigator, whatever
batches the samples came in, so a wake-up per published state is enough.
"""

from __future__ import annotations


class TimeGrid:
    """Ticks every ``1 / rate_hz`` of vehicle time from zero."""

    def __init__(self, rate_hz: float) -> None:
        self.period_us = round(1e6 / rate_hz)
        self.next_us = 0

    def passed(self, t_us: int) -> bool:
        """Whether ``t_us`` is at or past the next tick (which then moves past it)."""
        if t_us < self.next_us:
            return False
        self.next_us = (t_us // self.period_us + 1) * self.period_us
        return True
