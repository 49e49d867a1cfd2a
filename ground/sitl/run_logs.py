"""The on-board logs of one ``companion sim`` run, found and kept beside its truth CSV.

The vehicle writes them into its state directory, which holds every earlier run's logs too
(a fresh run does not empty it): the run's own are those that were not there before it.
"""

from __future__ import annotations

import logging
import shutil
from collections.abc import Collection, Sequence
from pathlib import Path

from companion.flight_log import LogDirectory

log = logging.getLogger(__name__)


def log_names(logs_dir: Path) -> set[str]:
    """The names of the logs in the directory now."""
    return {p.name for p in LogDirectory(logs_dir, 0).files()}


def new_logs(logs_dir: Path, before: Collection[str]) -> list[Path]:
    """The logs that appeared since ``before`` was taken, oldest first."""
    return [p for p in LogDirectory(logs_dir, 0).files() if p.name not in before]


def keep_beside(truth: Path, logs: Sequence[Path]) -> list[Path]:
    """Copies of ``logs`` next to the truth CSV: ``X.ulg`` for ``X.csv`` (``X_2.ulg``... if
    the run made more than one); the copies. The originals stay, for log download."""
    kept = []
    for i, path in enumerate(logs, 1):
        target = truth.with_name(truth.stem + ("" if i == 1 else f"_{i}") + ".ulg")
        try:
            shutil.copyfile(path, target)
        except OSError as exc:
            log.warning("cannot copy the flight log %s to %s: %s", path, target, exc)
            continue
        kept.append(target)
    return kept
