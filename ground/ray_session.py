"""Ray for the work that outgrows one process: flight campaigns and batches of logs.

``ray_session`` starts a local Ray instance (or joins ``address``) for the length of a
``with`` block; ``as_completed`` submits one task per item with its CPU need declared and
yields results as they finish, so the caller can write them and draw its progress bar.
Scheduling, placement and retries are Ray's; nothing here is a worker pool.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

log = logging.getLogger(__name__)
REPO = Path(__file__).resolve().parents[1]
# Ray would otherwise package the whole checkout for every ``uv run``; workers on this
# machine import the project from the same tree.
os.environ.setdefault("RAY_ENABLE_UV_RUN_RUNTIME_ENV", "0")


@dataclass
class Finished:
    """One task's end: its item, and its result or the error that ended it."""

    item: Any
    result: Any = None
    error: str | None = None
    running: int = 0  # tasks still running when this one was yielded


@contextmanager
def ray_session(address: str | None = None, num_cpus: int | None = None) -> Iterator[None]:
    """Ray, started here (local) or joined (``address``), and shut down afterwards."""
    import ray

    if address:
        # A cluster's workers get this checkout shipped to them; their Python
        # environment must hold the project's dependencies (same lock file).
        runtime_env = {"working_dir": str(REPO), "excludes": [".venv", ".git", "*.csv"]}
        ray.init(address=address, runtime_env=runtime_env, log_to_driver=False)
    else:
        ray.init(
            num_cpus=num_cpus or os.cpu_count() or 1,
            include_dashboard=False,
            log_to_driver=False,
            runtime_env={"env_vars": {"PYTHONPATH": _pythonpath()}},
        )
    log.info("ray: %s CPUs", ray.cluster_resources().get("CPU", 0))
    try:
        yield
    finally:
        ray.shutdown()


def _pythonpath() -> str:
    parts = [str(REPO), os.environ.get("PYTHONPATH", "")]
    return os.pathsep.join(p for p in parts if p)


def as_completed(
    fn: Callable[[Any], Any],
    items: Iterable[Any],
    cpus_per_task: float = 1.0,
    timeout_s: float | None = None,
) -> Iterator[Finished]:
    """Run ``fn(item)`` as one Ray task per item; yield each as it finishes.

    Only as many tasks are submitted as the cluster has CPUs for (Ray's pattern for
    limiting pending tasks), so a task's clock starts when it can run. A task that raises,
    or runs past ``timeout_s`` (it is then cancelled), is yielded with its error instead of
    a result; the others go on.
    """
    import ray

    remote = ray.remote(num_cpus=cpus_per_task, max_retries=0)(fn)
    slots = max(1, int(ray.cluster_resources().get("CPU", 1) // cpus_per_task))
    waiting = iter(items)
    running: dict[Any, tuple[Any, float]] = {}
    while True:
        while len(running) < slots and (item := next(waiting, _END)) is not _END:
            running[remote.remote(item)] = (item, time.monotonic())
        if not running:
            return
        done, _ = ray.wait(list(running), num_returns=1, timeout=0.5)
        for ref in done:
            item, _ = running.pop(ref)
            try:
                yield Finished(item, ray.get(ref), running=len(running))
            except Exception as exc:  # a task's failure is data here
                yield Finished(item, error=_short(exc), running=len(running))
        yield from _cancel_overdue(running, timeout_s)


_END = object()


def _cancel_overdue(running: dict[Any, tuple[Any, float]], timeout_s: float | None):
    import ray

    if timeout_s is None:
        return
    now = time.monotonic()
    for ref, (item, t0) in list(running.items()):
        if now - t0 > timeout_s:
            ray.cancel(ref, force=True)
            running.pop(ref)
            error = f"no result within {timeout_s:.0f} s: cancelled"
            yield Finished(item, error=error, running=len(running))


def _short(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[-1] if text else type(exc).__name__
