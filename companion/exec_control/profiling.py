"""Opt-in profiling of plug-in processes: where a plug-in's CPU goes, per function.

``COMPANION_PROFILE=DIR`` makes every plug-in process run its plug-in (init, steps, close)
under cProfile and write ``DIR/<name>.<pid>.prof`` when it stops; ``COMPANION_PROFILE_ONLY``
(comma-separated plug-in names) limits it to those. A composed process writes one file per
plug-in thread, named after the plug-in; a chained plug-in's steps (run on its producer's
thread) are in its producer's file. Times are the process's CPU time
(``time.process_time``; a composed process's threads each their own, ``time.thread_time``:
a function asleep in a wait costs nothing, the kernel's work in its system calls counts)
unless ``COMPANION_PROFILE_CLOCK=wall``. The variables reach the
plug-ins through the supervisor's and the fork server's environment, so

    COMPANION_PROFILE=/tmp/prof companion sim --plan qgc_plans/square.plan

profiles a whole real-time flight. Read a file with ``python -m pstats DIR/imu.123.prof``
(``sort tottime``, ``stats 20``). cProfile slows Python calls severalfold: compare
functions within one profile, never a profiled run's CPU with an unprofiled one's.

``COMPANION_WRAP="valgrind --tool=callgrind ..."`` (off when unset) starts plug-in processes
as that command followed by a fresh interpreter instead of forking them from the fork
server, so a tool that needs an ``exec`` (valgrind) sees them; ``COMPANION_WRAP_ONLY``
(comma-separated plug-in or composed process names) limits it to those.
``benchmarks/flight_instructions.py`` uses it to count a composed vehicle's instructions.
"""

from __future__ import annotations

import cProfile
import logging
import os
import shlex
import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

ENV_DIR = "COMPANION_PROFILE"
ENV_ONLY = "COMPANION_PROFILE_ONLY"
ENV_CLOCK = "COMPANION_PROFILE_CLOCK"
ENV_WRAP = "COMPANION_WRAP"
ENV_WRAP_ONLY = "COMPANION_WRAP_ONLY"
T = TypeVar("T")

log = logging.getLogger(__name__)


def profile_path(name: str) -> Path | None:
    """Where the profile of plug-in ``name`` goes; None when it is not profiled."""
    folder = os.environ.get(ENV_DIR, "")
    only = {n.strip() for n in os.environ.get(ENV_ONLY, "").split(",") if n.strip()}
    if not folder or (only and name not in only):
        return None
    return Path(folder) / f"{name}.{os.getpid()}.prof"


def exec_wrapper(name: str) -> list[str]:
    """The command to start plug-in process ``name`` under; [] (forked as usual) unless
    the environment asks for one."""
    only = {n.strip() for n in os.environ.get(ENV_WRAP_ONLY, "").split(",") if n.strip()}
    if only and name not in only:
        return []
    return shlex.split(os.environ.get(ENV_WRAP, ""))


def run_profiled(name: str, run: Callable[[], T], per_thread: bool = False) -> T:
    """``run()``, under cProfile when the environment asks for plug-in ``name``; timed by
    the calling thread's CPU clock when ``per_thread`` (a thread of a composed process)."""
    path = profile_path(name)
    if path is None:
        return run()
    wall = os.environ.get(ENV_CLOCK, "cpu") == "wall"
    cpu = time.thread_time if per_thread else time.process_time
    profiler = cProfile.Profile(time.perf_counter if wall else cpu)
    try:
        return profiler.runcall(run)
    finally:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            profiler.dump_stats(path)
        except OSError as exc:
            log.warning("profile of %s not written: %s", name, exc)
