"""Missions on disk: one JSON file per mission type, written atomically."""

from __future__ import annotations

import json
import logging
import zlib
from pathlib import Path

from companion.control.mission.items import MISSION_TYPES, MissionItem
from companion.messages import MissionChanged
from companion.params.atomic import atomic_write_text

log = logging.getLogger(__name__)
FILES = {0: "mission.json", 1: "fence.json", 2: "rally.json"}


class MissionStore:
    """The stored mission, fence and rally points; survives restarts and power loss."""

    def __init__(self, directory: Path | None) -> None:
        self.directory = directory
        self.items: dict[int, list[MissionItem]] = {t: [] for t in MISSION_TYPES}
        self.reload()

    def reload(self) -> MissionStore:
        """Read the files again (another process may have stored a new mission)."""
        if self.directory is not None:
            for mission_type in MISSION_TYPES:
                self.items[mission_type] = self._load(self.directory / FILES[mission_type])
        return self

    def checksum(self, mission_type: int) -> int:
        """CRC-32 of the list as it is held (the same list always gives the same number)."""
        text = json.dumps([item.as_dict() for item in self.items[mission_type]], sort_keys=True)
        return zlib.crc32(text.encode())

    def _load(self, path: Path) -> list[MissionItem]:
        try:
            raw = json.loads(path.read_text())
            return [MissionItem(**entry) for entry in raw]
        except FileNotFoundError:
            return []
        except (OSError, ValueError, TypeError) as exc:
            log.warning("mission file %s unreadable (%s): starting empty", path, exc)
            return []

    def replace(self, mission_type: int, items: list[MissionItem]) -> None:
        """Commit a whole new list (after a complete, valid upload)."""
        if self.directory is not None:
            text = json.dumps([item.as_dict() for item in items], indent=1)
            atomic_write_text(self.directory / FILES[mission_type], text)
        self.items[mission_type] = list(items)

    def changed(self, mission_type: int, t_us: int) -> MissionChanged:
        """What ``mission/changed`` says after ``mission_type`` was stored."""
        msg = MissionChanged(t_us=t_us, mission_type=mission_type)
        for t in MISSION_TYPES:
            msg.counts[t], msg.checksums[t] = len(self.items[t]), self.checksum(t)
        msg.count, msg.checksum = msg.counts[mission_type], msg.checksums[mission_type]
        return msg


class StoreFollower:
    """Keeps a process's copy of the store in step with ``mission/changed``.

    The lists are read again only when the link says a checksum differs from the one held
    here: storing an identical mission again changes nothing (a running mission goes on).
    """

    def __init__(self, store: MissionStore) -> None:
        self.store = store
        self.sums = {t: store.checksum(t) for t in MISSION_TYPES}
        self._seen: MissionChanged | None = None

    def follow(self, msg: MissionChanged | None) -> set[int]:
        """The mission types whose lists changed (reloaded from disk)."""
        # A Latest reader hands the same object back until a new value comes (every step
        # but a handful): once the lists held here matched it, it says nothing new.
        if msg is None or msg is self._seen:
            return set()
        if self._holds(msg):
            return set()
        self.store.reload()
        before, self.sums = self.sums, {t: self.store.checksum(t) for t in MISSION_TYPES}
        self._holds(msg)
        return {t for t in MISSION_TYPES if self.sums[t] != before[t]}

    def _holds(self, msg: MissionChanged) -> bool:
        """Whether the lists held here are the ones ``msg`` announces (then it is seen)."""
        announced = msg.checksums  # a ctypes array field: fetched once, not once a type
        if all(announced[t] == self.sums[t] for t in MISSION_TYPES):
            self._seen = msg
            return True
        return False
