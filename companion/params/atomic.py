"""Write a file so that a crash or power loss leaves either the old or the new content."""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
import time
from pathlib import Path

# A temporary file older than this was left by a writer killed between making it and
# renaming it over the file (a write takes milliseconds): it is removed at the next write.
# Younger ones may be another process's write in progress, and are left alone.
ORPHAN_AGE_S = 60.0


def atomic_write_text(path: Path, text: str, shared: bool = False) -> None:
    """Temp file in the same directory, fsync, rename over the old file, fsync the directory
    (and, the first time, the directory's own parent, so the new directory survives too).

    The file is its owner's alone (0600), as the vehicle's own state is, unless ``shared``:
    a file written for people and other programs (a saved parameter file, a plan, a systemd
    unit) keeps the mode of the file it replaces, or a new file's usual 0666 less the umask,
    as a plain write would give it."""
    created = not path.parent.is_dir()
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        if shared:
            os.fchmod(fd, _plain_write_mode(path))
        with os.fdopen(fd, "w") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    fsync_directory(path.parent)
    if created:
        fsync_directory(path.parent.parent)
    remove_orphans(path)


def _plain_write_mode(path: Path) -> int:
    """The permission bits ``open(path, "w")`` would leave: the old file's, or 0666 less the
    umask (read from /proc: setting it to read it would race with other threads' files)."""
    try:
        return stat.S_IMODE(path.stat().st_mode)
    except OSError:
        pass
    umask = 0o022
    with contextlib.suppress(OSError, ValueError):
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                umask = int(line.split()[1], 8)
    return 0o666 & ~umask


def remove_orphans(path: Path, now: float | None = None) -> list[Path]:
    """Remove the temporary files of ``path`` that killed writers left; those removed."""
    now = time.time() if now is None else now
    removed = []
    for tmp in path.parent.glob(f".{path.name}.*.tmp"):
        with contextlib.suppress(OSError):  # gone already: another writer swept it
            if now - tmp.stat().st_mtime > ORPHAN_AGE_S:
                tmp.unlink()
                removed.append(tmp)
    return removed


def fsync_directory(directory: Path) -> None:
    """Make the directory's entries (a new or renamed file in it) survive a power cut."""
    dir_fd = os.open(directory, os.O_RDONLY)
    try:
        os.fsync(dir_fd)
    finally:
        os.close(dir_fd)
