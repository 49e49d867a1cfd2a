"""The directory of flight logs: numbered files, the oldest removed past a disk budget.

A log being started lives under a hidden partial name (``.NNNN_label.ulg.part``, which no
listing shows) until its header is on disk; ``publish`` then renames it into view."""

from __future__ import annotations

import contextlib
import fcntl
import logging
import os
import re
from pathlib import Path
from typing import BinaryIO

from companion.params.atomic import fsync_directory

log = logging.getLogger(__name__)

_NAME = re.compile(r"^(\d{4,})_[A-Za-z0-9_-]*\.ulg$")
PARTIAL_SUFFIX = ".part"


class LogDirectory:
    """``NNNN_label.ulg`` files in one directory, numbered in the order they were started."""

    def __init__(self, path: Path, budget_bytes: int) -> None:
        self.path = path
        self.budget_bytes = budget_bytes

    def files(self) -> list[Path]:
        """The logs, oldest first."""
        if not self.path.is_dir():
            return []
        found = [(int(m.group(1)), p) for p in self.path.iterdir() if (m := _NAME.match(p.name))]
        return [p for _, p in sorted(found)]

    def new_path(self, label: str) -> Path:
        """The path of the next log (the directory is made if needed, durably: a power
        cut must not take the directory, and every log in it, away)."""
        if not self.path.is_dir():
            self.path.mkdir(parents=True, exist_ok=True)
            fsync_directory(self.path.parent)
        numbers = [int(m.group(1)) for p in self.files() if (m := _NAME.match(p.name))]
        number = max(numbers, default=0) + 1
        safe = re.sub(r"[^A-Za-z0-9_-]", "_", label)
        return self.path / f"{number:04d}_{safe}.ulg"

    def partial_path(self, path: Path) -> Path:
        """The hidden name ``path`` is written under until ``publish``."""
        return path.with_name(f".{path.name}{PARTIAL_SUFFIX}")

    def publish(self, partial: Path, path: Path) -> None:
        """Rename a partial log into view, durably (the directory is fsynced too)."""
        os.rename(partial, path)
        fsync_directory(self.path)

    def remove_partial(self) -> list[Path]:
        """Remove partial logs nobody writes (cut off before their header was on disk)."""
        if not self.path.is_dir():
            return []
        removed = []
        for path in self.path.glob(f".*.ulg{PARTIAL_SUFFIX}"):
            if being_written(path):
                continue
            with contextlib.suppress(OSError):
                path.unlink()
                removed.append(path)
        return removed

    def prune(self, keep: Path | None = None) -> list[Path]:
        """Remove the oldest logs (never ``keep``, the one being written) while the directory
        is over its budget; the removed paths."""
        files = self.files()
        sizes = {p: _size(p) for p in files}
        total = sum(sizes.values())
        removed: list[Path] = []
        for path in files:
            if total <= self.budget_bytes:
                break
            if path == keep:
                continue
            try:
                path.unlink()
            except OSError as exc:
                log.warning("cannot remove old log %s: %s", path, exc)
                continue
            total -= sizes[path]
            removed.append(path)
        return removed

    def erase(self) -> list[Path]:
        """Remove every log but one being written (another process holds it locked);
        the removed paths."""
        removed = []
        for path in self.files():
            if being_written(path):
                continue
            try:
                path.unlink()
            except OSError as exc:
                log.warning("cannot erase log %s: %s", path, exc)
                continue
            removed.append(path)
        return removed


def hold(stream: BinaryIO) -> None:
    """Mark a log as being written, for as long as ``stream`` is open (or its writer lives):
    an advisory lock, released by the kernel even when the writer is killed."""
    fcntl.flock(stream.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)


def being_written(path: Path) -> bool:
    """Whether a writer holds the log (see ``hold``)."""
    try:
        with path.open("rb") as probe:
            try:
                fcntl.flock(probe.fileno(), fcntl.LOCK_SH | fcntl.LOCK_NB)
            except OSError:
                return True
            with contextlib.suppress(OSError):
                fcntl.flock(probe.fileno(), fcntl.LOCK_UN)
    except OSError:
        return False
    return False


def _size(path: Path) -> int:
    try:
        return path.stat().st_size
    except OSError:
        return 0
