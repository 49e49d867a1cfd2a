"""Pacing: lockstep (wait until the drivers have read every byte) or a real-time factor."""

from __future__ import annotations

import logging
import time

from bridges.jsbsim.ptys import PtyPort

log = logging.getLogger(__name__)

STALL_S = 0.5  # a driver that reads nothing for this long is not waited for
SPIN_POLLS = 50  # polls that only yield the CPU before sleeping between polls
POLL_SLEEP_S = 50e-6


class Lockstep:
    """Waits, each frame, until every sensor line is drained by its driver.

    A driver that stops reading (it crashed, or is restarting) stalls one frame for at most
    ``STALL_S``; its line is then left out until the driver drains it again, so one dead
    driver slows the simulation down once instead of on every frame.
    """

    def __init__(self, ports: list[PtyPort]) -> None:
        self.ports = ports
        self.waiting_for = {p.name: True for p in ports}
        self.stalls = 0
        self.wait_s = 0.0

    def wait(self) -> None:
        """Return when the drivers have read what they were sent (or one stalled)."""
        started = time.perf_counter()
        polls = 0
        for port in self.ports:
            if not self.waiting_for[port.name]:
                self.waiting_for[port.name] = port.unread() == 0
        pending = [p for p in self.ports if self.waiting_for[p.name]]
        while pending:
            pending = [p for p in pending if p.unread() > 0]
            if not pending:
                break
            if time.perf_counter() - started > STALL_S:
                for port in pending:
                    log.warning("lockstep: %s driver is not reading; not waiting for it", port.name)
                    self.waiting_for[port.name] = False
                self.stalls += 1
                break
            polls += 1
            time.sleep(0 if polls < SPIN_POLLS else POLL_SLEEP_S)
        self.wait_s += time.perf_counter() - started


class RealTime:
    """Keeps simulation time at ``speed`` times wall time."""

    def __init__(self, speed: float) -> None:
        self.speed = speed
        self.start_wall: float | None = None
        self.late_s = 0.0  # the most the simulation has fallen behind

    def wait(self, t_s: float) -> None:
        """Sleep until wall time catches up with simulation time ``t_s``."""
        now = time.monotonic()
        if self.start_wall is None:
            self.start_wall = now - t_s / self.speed
        delay = self.start_wall + t_s / self.speed - now
        if delay > 0:
            time.sleep(delay)
        else:
            self.late_s = max(self.late_s, -delay)
