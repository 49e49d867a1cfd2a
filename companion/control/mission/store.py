"""Missions on disk: one JSON file per mission type, written atomically."""

from __future__ import annotations

import json
import logging
from pathlib import Path

from companion.control.mission.items import MISSION_TYPES, MissionItem
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

    def stamp(self, mission_type: int) -> int:
        """The stored list's modification time (ns; 0 when none): a change means reload."""
        if self.directory is None:
            return 0
        try:
            return (self.directory / FILES[mission_type]).stat().st_mtime_ns
        except FileNotFoundError:
            return 0

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
