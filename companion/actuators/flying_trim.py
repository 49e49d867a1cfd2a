"""The surface positions the aircraft was flying on lately, for the seconds it is alone.

When the supervisor dies the servo card is left holding whatever it was last sent until
the restarted vehicle commands it again (3 s or more). The controller's last frame may be
a full roll into a turn (held, it rolled the aircraft over); the card's centre positions
are not what the aircraft flies level on either: a C172 left on them rolled about 35° in
the first second and lost 13-16 m in a 3 s restart. An average of each surface's command
over the last seconds of flight is: on a straight leg, the aileron that holds the wings
level and the elevator that holds the height; in a turn, a gentle one. Pure: positions and
vehicle time in, positions out.
"""

from __future__ import annotations

import math

TAU_S = 2.0  # the average's time constant, vehicle seconds


class FlyingTrim:
    """Each channel's commanded position, averaged exponentially over about ``tau_s``."""

    def __init__(self, tau_s: float = TAU_S) -> None:
        self.tau_s = tau_s
        self.positions: dict[int, float] = {}
        self._t_s: float | None = None

    def update(self, positions: dict[int, int], t_s: float) -> None:
        """A command flown at ``t_s`` (servo → position)."""
        gap = 0.0 if self._t_s is None else max(0.0, t_s - self._t_s)
        weight = 1.0 - math.exp(-gap / self.tau_s)
        for servo, position in positions.items():
            average = self.positions.get(servo)
            self.positions[servo] = (
                float(position) if average is None else average + weight * (position - average)
            )
        self._t_s = t_s

    def position(self, servo: int, default: int) -> int:
        """The averaged position of ``servo`` (``default`` when it never flew)."""
        average = self.positions.get(servo)
        return default if average is None else round(average)
