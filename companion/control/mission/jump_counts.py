"""The DO_JUMP counts of the mission being flown, kept on disk for a controller restarted
in the air.

A controller whose process is killed (or the whole vehicle, its supervisor killed) takes
up the mission at the item the commander kept, but its executor starts with no jump
counted: a "repeat 3 times" loop half flown would be flown 3 more times. PX4 keeps the
count in the stored mission item; here the counts go to a small file beside the missions,
written atomically when a jump is counted, tagged with the mission they belong to.

They are taken up only by a controller whose first navigation solution was in the air (a
restart); one that starts on the ground forgets them, as does a controller stopped in the
ordinary way (disarmed).
"""

from __future__ import annotations

import json
import logging
import zlib
from collections.abc import Sequence
from dataclasses import astuple
from pathlib import Path

from companion.control.mission.items import MissionItem
from companion.params.atomic import atomic_write_text

log = logging.getLogger(__name__)

FILE_NAME = "jump_counts.json"


def mission_key(items: Sequence[MissionItem]) -> int:
    """A checksum of the mission's items: counts are only taken up for the same mission."""
    return zlib.crc32(repr([astuple(item) for item in items]).encode())


class JumpCounts:
    """Jump counts on disk: kept as they change, taken up once after a restart in the air.

    A write (fsync'd, a few milliseconds on a card) happens only when a jump is counted,
    never on a step that changed nothing.
    """

    def __init__(self, state_dir: Path | None = None) -> None:
        self.path = None if state_dir is None else state_dir / FILE_NAME  # None: kept nowhere
        self._may_take_up: bool | None = None  # None until the first solution is judged
        # What the file holds: (id of the items list, counts); None when not known.
        self._on_disk: tuple[int, dict[int, int]] | None = None

    def first_solution(self, landed: bool) -> None:
        """Where this controller's first navigation solution was: on the ground a new
        flight begins and the counts on disk are forgotten."""
        if self._may_take_up is not None:
            return
        self._may_take_up = not landed
        if landed:
            self.forget()

    def take_up(self, items: Sequence[MissionItem]) -> dict[int, int]:
        """The counts of ``items`` left by the controller before this one (once; empty
        unless this controller started in the air and they are the same mission's)."""
        if not self._may_take_up or self.path is None:
            return {}
        self._may_take_up = False
        try:
            saved = json.loads(self.path.read_text())
            if saved["mission"] != mission_key(items):
                return {}
            counts = {int(seq): int(done) for seq, done in saved["jumps"].items()}
        except FileNotFoundError:
            self._on_disk = (0, {})
            return {}
        except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
            log.warning("jump counts unreadable, starting from none: %s", exc)
            return {}
        log.info("jump counts taken up after a restart: %s", counts)
        self._on_disk = (id(items), dict(counts))
        return counts

    def keep(self, items: Sequence[MissionItem], counts: dict[int, int]) -> None:
        """Write ``counts`` of ``items`` if they differ from what the file holds (called at
        every step of a mission)."""
        if self.path is None or self._on_disk == (id(items), counts):
            return
        if not counts and self._on_disk is not None and not self._on_disk[1]:
            return  # none counted, none on disk: for any mission alike
        text = json.dumps(
            {"mission": mission_key(items), "jumps": {str(s): n for s, n in counts.items()}}
        )
        try:
            atomic_write_text(self.path, text)
        except OSError as exc:  # a full or read-only card must not stop the flight
            log.warning("cannot keep the jump counts: %s", exc)
            return
        self._on_disk = (id(items), dict(counts))

    def forget(self) -> None:
        """The flight is over (or a new one begins): no counts to take up."""
        if self.path is not None:
            self.path.unlink(missing_ok=True)
        self._on_disk = (0, {})
