"""Each endpoint's byte budget: protocol traffic first, telemetry only what fits.

A token bucket refilled at the link's byte rate (a serial link's baud/10, a configured
rate on UDP). Priority frames (heartbeats, acks, protocol replies) are always sent and
may overdraw the bucket; telemetry is sent only when the bucket covers it, otherwise that
sample is skipped and counted. Nothing queues, so nothing grows without bound. A SiK
radio's RADIO_STATUS with a filling transmit buffer lowers the rate further.
"""

from __future__ import annotations

from dataclasses import dataclass

BURST_S = 0.1  # the bucket holds this many seconds of traffic
MIN_SCALE = 0.1


@dataclass
class LinkBudget:
    """Token bucket in bytes."""

    rate_bytes_s: float
    tokens: float = 0.0
    last_s: float | None = None
    scale: float = 1.0  # lowered by RADIO_STATUS when the radio's buffer fills
    sent_priority: int = 0
    sent_telemetry: int = 0
    skipped: int = 0

    def _refill(self, now_s: float) -> None:
        if self.last_s is None:
            self.tokens = self.capacity
        else:
            self.tokens = min(
                self.capacity, self.tokens + (now_s - self.last_s) * self.rate_bytes_s * self.scale
            )
        self.last_s = now_s

    @property
    def capacity(self) -> float:
        return max(300.0, self.rate_bytes_s * self.scale * BURST_S)

    def take_priority(self, size: int, now_s: float) -> None:
        """Account for a frame that goes out whatever the budget says."""
        self._refill(now_s)
        self.tokens -= size
        self.sent_priority += 1

    def take_telemetry(self, size: int, now_s: float) -> bool:
        """True (and charged) when a telemetry frame fits the budget now."""
        self._refill(now_s)
        if self.tokens < size:
            self.skipped += 1
            return False
        self.tokens -= size
        self.sent_telemetry += 1
        return True

    def radio_status(self, txbuf_pct: int) -> None:
        """SiK radios report their transmit buffer fill: back off as it fills."""
        if txbuf_pct < 20:
            self.scale = max(MIN_SCALE, self.scale * 0.8)
        elif txbuf_pct < 50:
            self.scale = max(MIN_SCALE, self.scale * 0.95)
        elif txbuf_pct > 90:
            self.scale = min(1.0, self.scale * 1.05)
