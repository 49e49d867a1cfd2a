"""What the simulator tells the person at a hardware-in-the-loop bench, every few seconds.

The vehicle runs apart (on the board, or in another shell), so the only signs of it here
are the servo bytes it writes back. Each report gives the aircraft's state, the bytes each
line carried and dropped, and says in plain words when the servo line stays silent.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from typing import Protocol

from bridges.sensor_models.true_state import TrueState

log = logging.getLogger("bridges.jsbsim.hil")

REPORT_PERIOD_S = 5.0


class Line(Protocol):
    """What a report reads of a line (a pty or a real serial port)."""

    name: str
    path: str
    bytes_out: int
    dropped: int


class HilStatus:
    """Logs a line of state every ``REPORT_PERIOD_S`` of simulated time."""

    def __init__(self, lines: Mapping[str, Line], period_s: float = REPORT_PERIOD_S) -> None:
        self.lines = lines
        self.period_s = period_s
        self.next_s = period_s
        self.servo_seen = 0

    def report(self, s: TrueState, servo_bytes_in: int) -> None:
        """Log the state when a period has passed (called every physics frame)."""
        if s.t_s < self.next_s:
            return
        self.next_s += self.period_s
        lines = " ".join(
            f"{n} {p.bytes_out}B" + (f" ({p.dropped} dropped)" if p.dropped else "")
            for n, p in self.lines.items()
            if n != "servos"
        )
        log.info(
            "t %.0f s  alt %.1f m AGL  airspeed %.1f m/s  servos in %dB  out: %s",
            s.t_s,
            s.alt_agl_m,
            s.airspeed_m_s,
            servo_bytes_in,
            lines,
        )
        if servo_bytes_in == self.servo_seen:
            servos = self.lines["servos"].path
            log.info(
                "no servo bytes from the vehicle in the last %.0f s on %s: it writes them"
                " once armed; if it is armed, check its servo plug-in's device and rate",
                self.period_s,
                servos,
            )
        self.servo_seen = servo_bytes_in
