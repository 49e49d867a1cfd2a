"""A fixed grid of vehicle time, and the first sample at or past each of its ticks.

The navigator publishes on one (``nav.ins_ekf``'s ``publish_hz``) and the IMU driver may
wake its readers on the same one (``sensors.serial_imu``'s ``wake_hz``): the samples that
complete a navigation period are then exactly the ones that wake the navigator, whatever
batches the samples came in, so a wake-up per published state is enough.

On an aircraft a sample's stamp is when its first byte arrived, a fraction of a
millisecond either way, and the IMU's clock drifts against the board's: every few minutes
its samples come for a while right at a tick, some just before it and some just after. The
first sample at or past each tick was then one period late or early at random: a 50 Hz
navigator published at 10, 20 and 30 ms intervals and the controller ran at them (30 % of
its periods in one of four 60 s runs of ``benchmarks/latency.py`` on the hardware time
base). So a grid that took a sample within ``early_us(period)`` of its tick takes the
sample that comes up to that much before the next tick as well: it stays with the
samples near its ticks until they drift further off. A simulation's samples come on a
frame grid, never in that window, and are taken as before.
"""

from __future__ import annotations

EARLY_SHARE = 10  # the window before a tick is this fraction of the period


def early_us(period_us: int) -> int:
    """How long before its tick a grid that is with the samples takes one."""
    return period_us // EARLY_SHARE


class TimeGrid:
    """Ticks every ``1 / rate_hz`` of vehicle time from zero."""

    def __init__(self, rate_hz: float) -> None:
        self.period_us = round(1e6 / rate_hz)
        self.early_us = early_us(self.period_us)
        self.next_us = 0
        self._near = False  # the last sample taken was within early_us of its tick

    def passed(self, t_us: int) -> bool:
        """Whether ``t_us`` completes the next tick (which then moves past it): it is at or
        past the tick, or just before it while the samples come near the ticks."""
        next_us = self.next_us
        if t_us >= next_us:
            tick = t_us - t_us % self.period_us  # the newest tick at or before it
        elif self._near and t_us > next_us - self.early_us:
            tick = next_us
        else:
            return False
        self._near = t_us - tick < self.early_us
        self.next_us = tick + self.period_us
        return True
