"""One supervised plug-in process: spawn, stop, reap, restart back-off, CPU share."""

from __future__ import annotations

import json
import logging
import os
import signal
import subprocess
import sys
import time
from typing import Any

import psutil

from companion.exec_control.backoff import (
    FIRST_BACKOFF_S,
    MAX_BACKOFF_S,
    SECOND_BACKOFF_S,
    STABLE_AFTER_S,
)
from companion.exec_control.plugin_spec import PluginSpec
from companion.exec_control.profiling import exec_wrapper
from companion.exec_control.zygote import CHILD_ENV, ForkedProcess, ForkServer
from companion.messages import NAME_LEN, PluginHealth, PluginState, PluginStats

log = logging.getLogger(__name__)


class Child:
    """A plug-in instance and the OS process currently running it (if any)."""

    def __init__(self, spec: PluginSpec, base: dict[str, Any]) -> None:
        self.spec = spec
        self._argv_spec = json.dumps({**base, **_spec_dict(spec)})
        self.proc: subprocess.Popen[bytes] | ForkedProcess | None = None
        self.forker: ForkServer | None = None  # spawn a fresh interpreter when None
        self.state = PluginState.STOPPED
        self.restarts = 0
        self.wanted = False  # should be running (its group is started)
        self.started_at = 0.0
        self.next_start_at = 0.0
        self.backoff_s = FIRST_BACKOFF_S
        self.cpu_pct = 0.0
        self.rss_kib = 0
        self.stats = PluginStats()
        self.first_report = False  # the counters last absorbed were its first since start
        self._ps: psutil.Process | None = None

    @property
    def pid(self) -> int:
        return self.proc.pid if self.proc and self.proc.poll() is None else 0

    def start(self) -> None:
        """Start the plug-in process now: forked by the fork server, or else spawned."""
        self.stats = PluginStats()  # the dead process's counters are not the new one's
        wrapper = exec_wrapper(self.spec.name)  # a profiler's command: needs an exec
        forker = None if wrapper else self.forker
        forked = forker.spawn(self._argv_spec) if forker is not None else None
        self.proc = forked or subprocess.Popen(
            [*wrapper, sys.executable, "-m", "companion.exec_control.host_main", self._argv_spec],
            start_new_session=True,  # a terminal's Ctrl-C reaches the supervisor only
            env={**os.environ, **CHILD_ENV},
        )
        self._ps = psutil.Process(self.proc.pid)
        self._ps.cpu_percent(None)
        self.started_at = time.monotonic()
        self.state = PluginState.RUNNING
        log.info("started %s (%s) pid %d", self.spec.name, self.spec.kind, self.proc.pid)

    def flight_changed(self, running: bool) -> None:
        """The flight group started (True) or stopped: nothing to a plug-in's own process,
        which the supervisor starts or stops itself."""

    def reap(self, now: float) -> bool:
        """If the process died unasked, schedule its restart; True when it did."""
        code = self.proc.poll() if self.proc is not None else None
        if code is None:
            return False
        self.proc = None
        self._ps = None
        if not self.wanted:
            self.state = PluginState.STOPPED
            return False
        if now - self.started_at >= STABLE_AFTER_S:
            self.backoff_s = FIRST_BACKOFF_S
        self.next_start_at = now + self.backoff_s
        log.warning(
            "%s died (%s); restart in %.1f s", self.spec.name, _describe(code), self.backoff_s
        )
        self.backoff_s = min(max(self.backoff_s * 2, SECOND_BACKOFF_S), MAX_BACKOFF_S)
        self.state = PluginState.BACKOFF
        return True

    def restart_due(self, now: float) -> bool:
        return self.wanted and self.proc is None and now >= self.next_start_at

    def signal_stop(self) -> None:
        """Ask the process to stop (SIGTERM); it finishes its step and closes."""
        self.wanted = False
        if self.proc is not None and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)

    def kill(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()

    def wait_stopped(self, deadline: float) -> bool:
        """Wait until the process is gone or the deadline passes; True when gone."""
        if self.proc is None:
            return True
        try:
            self.proc.wait(timeout=max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            return False
        self.proc = None
        self._ps = None
        self.state = PluginState.STOPPED
        return True

    def sample_usage(self) -> None:
        """CPU share since the last call, and resident memory."""
        if self._ps is None:
            self.cpu_pct, self.rss_kib = 0.0, 0
            return
        try:
            with self._ps.oneshot():
                self.cpu_pct = self._ps.cpu_percent(None)
                self.rss_kib = self._ps.memory_info().rss // 1024
        except psutil.Error:
            self.cpu_pct, self.rss_kib = 0.0, 0

    def absorb(self, stats: PluginStats) -> bool:
        """Keep the plug-in's counters when they are this process's; True when kept."""
        if stats.name.decode(errors="replace") != self.spec.name or stats.pid != self.pid:
            return False
        self.first_report = stats.steps == 0  # sent after init, before any step
        self.stats = stats
        return True

    def health_rows(self) -> list[PluginHealth]:
        """The process's rows of the health table: its plug-in's."""
        return [self.health_row()]

    def health_row(self) -> PluginHealth:
        row = PluginHealth(state=int(self.state), pid=self.pid, restarts=self.restarts)
        row.name = self.spec.name.encode()[: NAME_LEN - 1]
        row.kind = self.spec.kind.encode()[:47]
        row.group = self.spec.group.encode()
        row.cpu_pct, row.rss_kib = self.cpu_pct, self.rss_kib
        s = self.stats
        row.frames_ok, row.frames_bad, row.dropped = s.frames_ok, s.frames_bad, s.dropped
        row.refused, row.bytes_in, row.counted_us = s.refused, s.bytes_in, s.t_us
        row.step_p50_us, row.step_p99_us = s.step_p50_us, s.step_p99_us
        return row


def _spec_dict(spec: PluginSpec) -> dict[str, Any]:
    return {
        "name": spec.name,
        "kind": spec.kind,
        "group": spec.group,
        "settings": spec.settings,
        "nice": spec.nice,
    }


def _describe(code: int) -> str:
    if code < 0:
        try:
            return f"signal {signal.Signals(-code).name}"
        except ValueError:
            return f"signal {-code}"
    return f"exit status {code}"


def process_exists(pid: int) -> bool:
    """True while a process with this pid exists (for tests and diagnostics)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
