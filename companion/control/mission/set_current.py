"""MISSION_SET_CURRENT / DO_SET_MISSION_CURRENT, as the flight controller takes them.

The commander counts the set-currents it accepts (``VehicleStatus.mission_jumps``) and
says the item of the last (``mission_jump_to``). The controller acts on the count only
when it grows from one it has seen: a count seen first (a controller started again, or a
commander that came back from its flight state) is not a jump, and the item the commander
reports as the mission's progress (``mission_first``, overwritten with what the controller
said last) is never taken for one. A jump seen in another mode waits for the mission to
be flown again: a paused mission goes on from the new item, not its own.
"""

from __future__ import annotations

from collections.abc import Sequence

from companion.control.mission.items import MissionItem
from mavlink_dialect import companion as d


def first_takeoff(items: Sequence[MissionItem]) -> int:
    """The first take-off item's index (-1: the mission has none)."""
    return next((i for i, it in enumerate(items) if it.command == d.MAV_CMD_NAV_TAKEOFF), -1)


class MissionJumps:
    """The set-currents the controller has seen, and the one it has yet to fly."""

    def __init__(self) -> None:
        self.seen: int | None = None  # the commander's count when last seen
        self.pending: int | None = None  # the item to fly to when the mission runs

    def see(self, count: int, item: int) -> None:
        """The commander's count and item, every step."""
        if self.seen is not None and count > self.seen:
            self.pending = item
        self.seen = count

    def take(self, items: Sequence[MissionItem]) -> int | None:
        """The item to go to now (once), None when there is none for ``items``."""
        item, self.pending = self.pending, None
        return item if item is not None and 0 <= item < len(items) else None

    def forget(self) -> None:
        """A new mission was stored: an item set for the old one means nothing."""
        self.pending = None
