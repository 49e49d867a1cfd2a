"""Atomic writes (parameters, missions, fence, rally) killed with SIGKILL mid-write: the
file holds the old or the new content, never a mix, and a killed writer's temporary file
is swept later."""

from __future__ import annotations

import json
import logging
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

from companion.params.atomic import ORPHAN_AGE_S, atomic_write_text, remove_orphans

KILLS = 20
WRITER = """
import json, sys
from pathlib import Path
from companion.params.atomic import atomic_write_text
path = Path(sys.argv[1])
n = json.loads(path.read_text())["n"] if path.exists() else 0
print("writing", flush=True)
while True:
    n += 1
    atomic_write_text(path, json.dumps({"n": n, "pad": [n] * 5000}))
"""


def test_a_writer_killed_mid_write_leaves_the_old_or_the_new_file(tmp_path: Path) -> None:
    path = tmp_path / "state" / "params.json"
    rng = random.Random(41)
    last = 0
    for _ in range(KILLS):
        writer = subprocess.Popen(
            [sys.executable, "-c", WRITER, str(path)], stdout=subprocess.PIPE, text=True
        )
        assert writer.stdout is not None and writer.stdout.readline().strip() == "writing"
        time.sleep(rng.uniform(0.005, 0.08))  # somewhere in a write, or between two
        os.kill(writer.pid, signal.SIGKILL)
        writer.wait(10)
        writer.stdout.close()
        stored = json.loads(path.read_text())  # whole: it parses
        assert stored["pad"] == [stored["n"]] * 5000, "a mix of two writes"
        assert stored["n"] >= last, "an older content than the last one read"
        last = stored["n"]
    assert last > KILLS, "the writers wrote"
    # Temporary files of killed writers: swept once they are old enough to be orphans.
    left = set(path.parent.glob(".params.json.*.tmp"))
    logging.getLogger(__name__).info("%d kills left %d temporary files", KILLS, len(left))
    assert set(remove_orphans(path, now=time.time() + ORPHAN_AGE_S + 1)) == left
    assert not list(path.parent.glob(".params.json.*.tmp"))


def test_a_write_sweeps_old_orphans_and_leaves_a_write_in_progress(tmp_path: Path) -> None:
    path = tmp_path / "missions" / "fence.json"
    atomic_write_text(path, "[]")
    orphan = path.parent / ".fence.json.abc123.tmp"
    in_progress = path.parent / ".fence.json.def456.tmp"
    other = path.parent / ".mission.json.ghi789.tmp"
    for tmp in (orphan, in_progress, other):
        tmp.write_text("[{")
    old = time.time() - ORPHAN_AGE_S - 5
    os.utime(orphan, (old, old))
    os.utime(other, (old, old))
    atomic_write_text(path, "[1]")
    assert json.loads(path.read_text()) == [1]
    assert not orphan.exists(), "a killed writer's file is swept"
    assert in_progress.exists(), "another process's write in progress is left alone"
    assert other.exists(), "another file's temporaries are its own writes' to sweep"


def test_a_shared_file_gets_a_plain_writes_mode_and_state_stays_private(tmp_path: Path) -> None:
    """A saved parameter file or plan is for people and other programs: readable as a
    plain write would leave it (0666 less the umask), a replaced one keeps its mode; the
    vehicle's own state is its owner's alone."""
    old_umask = os.umask(0o027)
    try:
        shared = tmp_path / "backup.params"
        atomic_write_text(shared, "x\n", shared=True)
        assert shared.stat().st_mode & 0o777 == 0o640
        shared.chmod(0o604)
        atomic_write_text(shared, "y\n", shared=True)
        assert shared.stat().st_mode & 0o777 == 0o604 and shared.read_text() == "y\n"
        private = tmp_path / "state" / "params.json"
        atomic_write_text(private, "{}")
        assert private.stat().st_mode & 0o777 == 0o600
    finally:
        os.umask(old_umask)
