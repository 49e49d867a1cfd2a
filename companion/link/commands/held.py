"""Commands for a flight plug-in, held until it can hear them.

START starts the flight group's plug-ins at once, and the health table shows each running
from then on, before it has made its bus readers: a command put on ``link/commands`` in
that window is lost (the channel keeps nothing for a reader that comes later), and the
ground station would hear FAILED ten seconds on. A script that arms and at once sets a
servo, takes a photo or drops a payload meets that window, longer on a small board. So a
command for a flight plug-in (the flight controller, the servo output) waits in the link
until that plug-in has reported its counters since the flight group started (it first
reports them after ``init``, its readers made); one still held when its ack's wait ends is
dropped, as the ack then says FAILED.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field

from companion.messages import PluginState, SystemHealth, VehicleCommand

log = logging.getLogger(__name__)


@dataclass
class HeldCommands:
    """The commands held, and when the link saw the flight group start."""

    # (the plug-in's kind, when to give up (monotonic s), the command)
    held: list[tuple[bytes, float, VehicleCommand]] = field(default_factory=list)
    flight_since_us: int | None = None  # the vehicle clock when the link saw it start

    def follow(self, health: SystemHealth | None, now_us: int) -> None:
        """The newest health table, at ``now_us`` on the vehicle clock."""
        if health is None or not health.flight_running:
            self.flight_since_us = None
        elif self.flight_since_us is None:
            self.flight_since_us = now_us

    def listening(self, health: SystemHealth | None, kind: bytes) -> bool:
        """Whether the plug-in of ``kind`` runs and has reported since the flight group
        started (one a config puts in the core group: since it started)."""
        row = health.row_of_kind(kind) if health is not None else None
        if row is None or row.state != PluginState.RUNNING:
            return False
        if row.group != b"flight":
            return row.counted_us > 0
        return self.flight_since_us is not None and row.counted_us >= self.flight_since_us

    def hold(self, kind: bytes, deadline_s: float, command: VehicleCommand) -> None:
        self.held.append((kind, deadline_s, command))

    def release(
        self,
        health: SystemHealth | None,
        now_s: float,
        publish: Callable[[VehicleCommand], None],
    ) -> None:
        """Publish the held commands whose plug-in listens now, in the order they came;
        drop those whose wait has ended."""
        if not self.held:
            return
        kept = []
        for kind, deadline_s, command in self.held:
            if self.listening(health, kind):
                publish(command)
            elif now_s < deadline_s:
                kept.append((kind, deadline_s, command))
            else:
                log.warning("command %d for %s: never heard, dropped", command.command, kind)
        self.held = kept
