"""Run a real vehicle (``companion run``) in a subprocess for a test, and clean up after.

Each vehicle gets its own bus namespace, so tests never see each other's channels, and
teardown checks that nothing is left running or in /dev/shm.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

from companion.bus.namespace import cleanup_namespace, leftover_files
from companion.bus.node import BusNode
from companion.messages import SystemHealth
from companion.testing import processes
from companion.testing.processes import LoggedProcess, unique_namespace
from mavlink_dialect import companion as d

REPO = Path(__file__).resolve().parents[2]
T = TypeVar("T")
__all__ = [
    "REPO", "Vehicle", "assert_clean", "companion_env", "set_param", "unique_namespace",
    "wait_for",
]  # fmt: skip


def wait_for(predicate: Callable[[], T], timeout_s: float, what: str, period_s: float = 0.05) -> T:
    """Poll a test condition until it is truthy (tests may poll; the vehicle never does)."""
    deadline = time.monotonic() + timeout_s
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout_s} s waiting for {what}")
        time.sleep(period_s)


def set_param(watcher: Any, name: str, value: float) -> None:
    """A parameter written as a ground station writes it (PARAM_SET, REAL32), and its echo
    with that value awaited (30 s)."""
    watcher.mav.param_set_send(1, 1, name.encode(), value, d.MAV_PARAM_TYPE_REAL32)
    watcher.until(lambda m: m.get_type() == "PARAM_VALUE" and m.param_id == name
                  and m.param_value == value, 30, f"{name} = {value}")  # fmt: skip


def companion_env(namespace: str) -> dict[str, str]:
    """The plug-in's environment, with the repository importable (the tests' plug-ins)."""
    return processes.companion_env(namespace, [REPO])


class Vehicle:
    """A ``companion run`` process and a bus node to watch it from the test."""

    def __init__(self, config_text: str, tmp: Path, namespace: str | None = None) -> None:
        self.namespace = namespace or unique_namespace()
        self.config = tmp / "vehicle.toml"
        self.config.write_text(textwrap.dedent(config_text))
        self.proc: LoggedProcess | None = None
        self.bus: BusNode | None = None
        self._health: Any = None
        # The vehicle's output goes to a file: a pipe nobody reads until the end blocks the
        # vehicle once 64 KiB of log lines have piled up (a link stopped before its first
        # heartbeat that way).
        self.log_path = tmp / "vehicle.log"
        # Another way to start it (a systemd unit's ExecStart), and what else it is given.
        self.command: list[str] | None = None
        self.extra_env: dict[str, str] = {}

    def start(self) -> Vehicle:
        command = self.command or [sys.executable, "-m", "companion", "run", "-c", str(self.config)]
        env = {**companion_env(self.namespace), **self.extra_env}
        self.proc = LoggedProcess(command, self.log_path, env, cwd=REPO)
        self.bus = BusNode(self.namespace, "test")
        self._health = self.bus.latest_reader("system/health")
        return self

    def health(self) -> SystemHealth | None:
        return self._health.get()

    def row(self, name: str) -> Any:
        health = self.health()
        if health is None:
            return None
        return next((r for r in health.rows() if r.name.decode() == name), None)

    def wait_running(self, name: str, timeout_s: float = 60.0) -> int:
        """Wait until the plug-in reports a pid in a fresh health table; return it."""
        return wait_for(lambda: (r := self.row(name)) is not None and r.pid, timeout_s, name)

    def all_pids(self) -> list[int]:
        return self.proc.tree() if self.proc is not None else []

    def stop(self, sig: int = signal.SIGTERM, timeout_s: float = 5.0) -> float:
        """Signal the supervisor and wait for it; return how long the shutdown took."""
        assert self.proc is not None
        started = time.monotonic()
        self.proc.send_signal(sig)
        self.proc.wait(timeout=timeout_s)
        return time.monotonic() - started

    def output(self) -> str:
        """What the vehicle printed, once it has exited."""
        if self.proc is None or self.proc.poll() is None or not self.log_path.exists():
            return ""
        return self.log_path.read_text(errors="replace")

    def close(self) -> None:
        """Stop everything the test started, whatever state the test left it in."""
        pids = self.all_pids()
        if self.proc is not None and self.proc.poll() is None:
            with contextlib.suppress(subprocess.TimeoutExpired):
                self.stop()
        for pid in pids:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        if self.bus is not None:
            self.bus.close()
            self.bus = None
        cleanup_namespace(self.namespace)


def assert_clean(namespace: str) -> None:
    """Nothing of the namespace may remain in /dev/shm."""
    left = leftover_files(namespace)
    assert not left, f"stale shared memory left behind: {[p.name for p in left]}"
