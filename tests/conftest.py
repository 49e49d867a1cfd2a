"""Shared fixtures: a real vehicle per test, each on its own bus namespace.

``COMPANION_TEST_STRESS=1`` runs the whole session on a busy machine: one CPU-bound
Python process per core for as long as the tests run (a real companion computer is never
idle, and the vehicle must fly the same whatever the scheduler does).
"""

from __future__ import annotations

import compileall
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from companion.exec_control.config import STATE_ENV
from tests.support.vehicle import REPO, Vehicle

STRESS_ENV = "COMPANION_TEST_STRESS"
_HOG = "while True:\n    pass\n"
_hogs: list[subprocess.Popen[bytes]] = []
_state_roots: list[str] = []  # the default state directories this process made


def pytest_sessionstart(session: pytest.Session) -> None:
    """Compile the project's modules once; start the CPU hogs when asked for a busy machine."""
    _compile_project()
    # A vehicle started without a state directory of its own makes one under the config's
    # default, ~/.local/state/companion/NAME/NAMESPACE: a session's hundreds of them stayed
    # in the home directory. Under a directory of the session's, removed at its end.
    if not os.environ.get(STATE_ENV):
        _state_roots.append(tempfile.mkdtemp(prefix="companion-test-state-"))
        os.environ[STATE_ENV] = _state_roots[-1]
    # Under pytest-xdist the controller starts the hogs once; its workers start none.
    worker = "PYTEST_XDIST_WORKER" in os.environ
    if os.environ.get(STRESS_ENV, "") not in ("", "0") and not worker:
        for _ in range(os.cpu_count() or 2):
            _hogs.append(subprocess.Popen([sys.executable, "-c", _HOG]))


def _compile_project() -> None:
    """Every vehicle a test starts imports the project's modules afresh (the generated
    MAVLink dialect alone is 1.9 MB of source). Where PYTHONDONTWRITEBYTECODE keeps Python
    from caching what it compiles, each start compiled them all again: written once here,
    the bytecode is read by every process after (compileall writes it whatever that says)."""
    for package in ("companion", "bridges", "ground", "mavlink_dialect"):
        compileall.compile_dir(REPO / package, quiet=1)


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """End the hogs this session started (by their own pids)."""
    for hog in _hogs:
        hog.kill()
    for hog in _hogs:
        hog.wait()
    _hogs.clear()
    for root in _state_roots:
        shutil.rmtree(root, ignore_errors=True)
    _state_roots.clear()


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """``-n auto`` (the addopts): two workers per core the session may run on, and no more
    than one per GiB of memory. A lockstep flight waits on its vehicle's chain of processes
    most of the time, so one worker per core left the cores partly idle (the timings:
    docs/dev/testing.md)."""
    memory_gib = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") // 2**30
    return max(1, min(2 * len(os.sched_getaffinity(0)), memory_gib))


def pytest_report_header(config: pytest.Config) -> str | None:
    """Say when the session runs under stress."""
    if os.environ.get(STRESS_ENV, "") not in ("", "0"):
        return f"{STRESS_ENV}: one CPU hog per core ({os.cpu_count()}) for the session"
    return None


@pytest.fixture
def vehicle_factory(tmp_path: Path) -> Iterator[Callable[..., Vehicle]]:
    """Start ``companion run`` on a config text; everything is stopped afterwards."""
    made: list[Vehicle] = []

    def make(config_text: str, namespace: str | None = None) -> Vehicle:
        sub = tmp_path / f"v{len(made)}"
        sub.mkdir()
        vehicle = Vehicle(config_text, sub, namespace).start()
        made.append(vehicle)
        return vehicle

    yield make
    for vehicle in made:
        vehicle.close()
