"""When each downlink frame goes: per-message rates, paced to what the serial line carries.

The thesis put a FIFO between the plug-ins and the modem so nobody blocked on the slow
link, and noted the link must not be overwhelmed. Here nothing queues at all: each
message kind keeps only its newest value, a frame is sent when its kind is due and the
previous frame has left the wire, and a kind whose data is stale is skipped. So a 9600
baud modem carries at most 38.4 frames a second and the ground station always gets the
latest attitude, never a backlog.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from bridges.text_link.frames import FRAME_BYTES

BITS_PER_BYTE = 10  # 8N1: start bit, eight data bits, stop bit


def frames_per_second(baud: int) -> float:
    """How many 25-byte frames a second the line carries at ``baud``."""
    return baud / (BITS_PER_BYTE * FRAME_BYTES)


def check_rates(rates_hz: dict[str, float], baud: int) -> None:
    """Raise ValueError when the rates do not fit the line or make no sense."""
    if baud <= 0:
        raise ValueError(f"baud rate {baud} must be positive")
    for kind, rate in rates_hz.items():
        if not (math.isfinite(rate) and rate >= 0):
            raise ValueError(
                f"{kind} rate {rate:g} Hz must be a finite number of frames a second, not negative"
            )
    total = sum(rates_hz.values())
    capacity = frames_per_second(baud)
    if total > capacity:
        parts = " + ".join(f"{kind} {rate:g} Hz" for kind, rate in rates_hz.items())
        raise ValueError(
            f"{parts} = {total:g} frames/s, more than {baud} baud carries "
            f"({capacity:.1f} frames of {FRAME_BYTES} bytes a second)"
        )


@dataclass
class DownlinkSchedule:
    """Decides which kind of frame, if any, to send now."""

    rates_hz: dict[str, float]
    baud: int
    next_due_s: dict[str, float] = field(default_factory=dict)
    wire_free_s: float = 0.0  # when the last frame written has left the line

    def __post_init__(self) -> None:
        check_rates(self.rates_hz, self.baud)
        self.frame_s = 1.0 / frames_per_second(self.baud)

    def due(self, now_s: float, ready: set[str]) -> str | None:
        """The kind to send now, of those with fresh data in ``ready``; the most overdue first.

        A kind that is due without data waits a whole period: when its data comes back it
        goes at its rate, not in a burst, and the caller's sleep is never zero.
        """
        best: str | None = None
        for kind, rate in self.rates_hz.items():
            if rate <= 0:
                continue
            due = self.next_due_s.setdefault(kind, now_s)
            if due > now_s:
                continue
            if kind not in ready:
                self.next_due_s[kind] = now_s + 1.0 / rate
            elif best is None or due < self.next_due_s[best]:
                best = kind
        return best if now_s >= self.wire_free_s else None

    def sent(self, kind: str, now_s: float) -> None:
        """A frame of ``kind`` went out at ``now_s``."""
        period = 1.0 / self.rates_hz[kind]
        due = self.next_due_s.get(kind, now_s) + period
        # After a pause (no data, a busy line) start afresh rather than send a burst.
        self.next_due_s[kind] = due if due > now_s else now_s + period
        self.wire_free_s = max(now_s, self.wire_free_s) + self.frame_s

    def wait_s(self, now_s: float) -> float:
        """Seconds until something could be due (for the caller's sleep)."""
        dues = [self.next_due_s.get(k, now_s) for k, r in self.rates_hz.items() if r > 0]
        soonest = max(self.wire_free_s, min(dues, default=math.inf))
        return max(0.0, soonest - now_s)
