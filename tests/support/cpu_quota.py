"""A CPU quota for a process tree, as a small board's one slow core: a cgroup v1 child of
``/sys/fs/cgroup/cpu`` (``cpu.cfs_quota_us`` per ``cpu.cfs_period_us``), with the same
child under ``cpuacct`` (where it is mounted apart) to count the CPU the tree used.

A process joins before it starts its own children (``preexec_fn=quota.join``), so every
process it forks is confined too. The cgroups are removed on ``close`` and at exit:
processes still in them are moved back to the root first (a cgroup with tasks cannot be
removed), so nothing is left behind even when a run fails.
"""

from __future__ import annotations

import atexit
import itertools
import logging
import os
import time
from pathlib import Path

log = logging.getLogger(__name__)

CPU_ROOT = Path("/sys/fs/cgroup/cpu")
ACCT_ROOT = Path("/sys/fs/cgroup/cpuacct")
PERIOD_US = 10_000
# The kernel refuses a quota under 1 ms (EINVAL); below 10 % of a core the period grows
# instead (7.5 %: 1 ms in 13.3 ms), so the throttled stretches are longer there.
MIN_QUOTA_US = 1_000
_serial = itertools.count()


def unusable_reason() -> str | None:
    """Why a quota cannot be made here (None: it can)."""
    if not (CPU_ROOT / "cpu.cfs_quota_us").exists():
        return f"no cgroup v1 cpu controller at {CPU_ROOT}"
    if not os.access(CPU_ROOT, os.W_OK):
        return f"{CPU_ROOT} is not writable (needs root)"
    return None


def period_and_quota(percent: float) -> tuple[int, int]:
    """The period and quota, µs, that give ``percent`` of one core."""
    period = max(PERIOD_US, round(MIN_QUOTA_US * 100 / percent))
    return period, max(MIN_QUOTA_US, round(period * percent / 100))


class CpuQuota:
    """``percent`` of one core (None: no limit, only counted) for the processes that join.

    ``shares`` is the cgroup's weight against the other processes of the machine (1024:
    one process at nice 0, however many processes join): a vehicle of 14 processes in a
    cgroup at 1024 gets one process's share of a busy machine; a large weight lets it take
    up to its quota first, as it would on a board of its own."""

    def __init__(
        self, percent: float | None, tag: str = "companion_quota", shares: int = 1024
    ) -> None:
        self.percent = percent
        self.name = f"{tag}_{os.getpid()}_{next(_serial)}"
        roots = [CPU_ROOT]
        if ACCT_ROOT.exists() and ACCT_ROOT.resolve() != CPU_ROOT.resolve():
            roots.append(ACCT_ROOT)
        self.dirs: list[Path] = []
        atexit.register(self.close)
        for root in roots:
            path = root / self.name
            path.mkdir()
            self.dirs.append(path)
        self.period_us, self.quota_us = period_and_quota(percent) if percent else (PERIOD_US, -1)
        self._write("cpu.cfs_period_us", self.period_us)
        self._write("cpu.cfs_quota_us", self.quota_us)
        self._write("cpu.shares", shares)

    def _write(self, name: str, value: int) -> None:
        (self.dirs[0] / name).write_text(f"{value}\n")

    def join(self, pid: int | None = None) -> None:
        """Put a process (this one by default) in the quota; as a ``preexec_fn``, the child
        about to exec joins, and everything it starts afterwards is confined with it."""
        for path in self.dirs:
            (path / "cgroup.procs").write_text(f"{pid or os.getpid()}\n")

    def pids(self) -> list[int]:
        """The processes in the quota now."""
        text = (self.dirs[0] / "cgroup.procs").read_text() if self.dirs else ""
        return [int(p) for p in text.split()]

    def used_s(self) -> float:
        """CPU seconds the processes in the quota have used since it was made."""
        for path in self.dirs:
            usage = path / "cpuacct.usage"
            if usage.exists():
                return int(usage.read_text()) / 1e9
        return float("nan")

    def throttled(self) -> tuple[int, int, float]:
        """Periods run, periods in which the quota ran out, and the seconds spent stopped."""
        stat = dict(ln.split() for ln in (self.dirs[0] / "cpu.stat").read_text().splitlines())
        return (int(stat["nr_periods"]), int(stat["nr_throttled"]),
                int(stat["throttled_time"]) / 1e9)  # fmt: skip

    def close(self) -> None:
        """Remove the cgroups; processes still in them go back to the root's."""
        for path in reversed(self.dirs):
            for _ in range(50):
                try:
                    for pid in (path / "cgroup.procs").read_text().split():
                        _move(path.parent, pid)
                    path.rmdir()
                    break
                except FileNotFoundError:
                    break
                except OSError as exc:  # a process forked while we moved the others
                    log.debug("removing %s: %s", path, exc)
                    time.sleep(0.02)
            else:
                log.warning("could not remove cgroup %s", path)
        self.dirs = []
        atexit.unregister(self.close)

    def __enter__(self) -> CpuQuota:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _move(root: Path, pid: str) -> None:
    try:
        (root / "cgroup.procs").write_text(f"{pid}\n")
    except ProcessLookupError:  # it ended meanwhile
        pass
