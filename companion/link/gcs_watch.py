"""Which ground stations the vehicle hears, and how long since the last one spoke.

A ground station is whatever sends a HEARTBEAT with type MAV_TYPE_GCS (QGroundControl,
MAVProxy, MAVSDK configured as a ground station). The failsafe that returns home when the
link is lost reads the silence.
"""

from __future__ import annotations

import math
from typing import Any

from companion.link.codec import dialect as d
from companion.link.microservice import Outgoing, Peer

STATUS_PERIOD_S = 0.2  # link/status (the silence) five times a second once one was heard
UNHEARD_STATUS_PERIOD_S = 1.0  # before: the silence is "never heard", which changes nothing
# A link awake anyway publishes link/status this much ahead of its time (and keeps its
# grid), as the streams ride ATTITUDE's wake-ups (stream_schedule.BATCH_S): a timer of its
# own woke the link five times a second more.
STATUS_EARLY_S = 0.1


class GcsWatch:
    """A service that only listens."""

    handles = frozenset({"HEARTBEAT"})

    def __init__(self) -> None:
        self.last_heard_s: float | None = None
        self.next_status_s = 0.0  # when link/status is next published

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        if msg.type == d.MAV_TYPE_GCS:
            self.last_heard_s = now_s
        return []

    def tick(self, now_s: float) -> list[Outgoing]:
        return []

    @property
    def heard(self) -> bool:
        """Whether any ground station has spoken yet."""
        return self.last_heard_s is not None

    def status_period_s(self) -> float:
        """How often link/status is worth publishing."""
        return STATUS_PERIOD_S if self.heard else UNHEARD_STATUS_PERIOD_S

    def status_due(self, now_s: float) -> bool:
        """Whether link/status is to be published now (then its next time is set): from
        ``STATUS_EARLY_S`` (at most half its period) ahead of its time."""
        period = self.status_period_s()
        early = min(STATUS_EARLY_S, 0.5 * period)
        if now_s < self.next_status_s - early:
            return False
        self.next_status_s = max(self.next_status_s + period, now_s + period - early)
        return True

    def next_due(self) -> float:
        """The link's wake-up for link/status once a ground station was heard; before, the
        silence is "never heard", and link/status rides other wake-ups."""
        return self.next_status_s if self.heard else math.inf

    def silence_s(self, now_s: float) -> float:
        """Seconds since the last ground-station heartbeat; NaN before the first."""
        return math.nan if self.last_heard_s is None else now_s - self.last_heard_s
