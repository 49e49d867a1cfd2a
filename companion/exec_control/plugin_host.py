"""The process a plug-in runs in: ``python -m companion.exec_control.plugin_host SPEC``.

It imports the plug-in by name, gives it its context, calls step() until told to stop
(SIGTERM/SIGINT), and publishes the plug-in's counters and step-time percentiles on
``system/plugin_stats`` once a second. A plug-in that raises ends the process with a
non-zero status; the supervisor restarts it.
"""

from __future__ import annotations

import ctypes
import logging
import os
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from companion.bus.clock import MonotonicClock, SimulationClock, VehicleClock
from companion.bus.node import BusNode
from companion.bus.patterns import Writer
from companion.exec_control.priority import apply_priority
from companion.exec_control.profiling import run_profiled
from companion.exec_control.registry import load
from companion.messages import NAME_LEN, PluginState, PluginStats
from companion.params import ParamDecl
from companion.plugin import Plugin, PluginContext

if TYPE_CHECKING:
    import iceoryx2 as iox2

EXIT_INIT_FAILED = 3
EXIT_STEP_FAILED = 4
STATS_PERIOD_S = 1.0
# How often late readers of this process's Latest channels are handed the last value.
CONNECTIONS_PERIOD_S = 0.05
_PR_SET_PDEATHSIG = 1
_PR_SET_NAME = 15

log = logging.getLogger("companion.plugin_host")


def set_name(name: str) -> None:
    """The plug-in's name for ps and top, on the calling thread (a forked process keeps its
    parent's otherwise; a composed process's threads would all show the process's)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_NAME, ctypes.c_char_p(name.encode()[:15]), 0, 0, 0)
    except (OSError, AttributeError):  # not Linux: the name is only cosmetic
        pass


def die_with_parent() -> None:
    """Ask Linux to SIGTERM this process when the supervisor dies, even by SIGKILL."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
    except (OSError, AttributeError):  # not Linux: the supervisor's own shutdown still works
        return
    if os.getppid() == 1:  # the parent died before prctl took effect
        sys.exit(0)


class StepTimer:
    """Step durations of the last few hundred steps, for p50/p99."""

    def __init__(self, size: int = 512) -> None:
        self._us: deque[float] = deque(maxlen=size)
        self.steps = 0

    def add(self, seconds: float) -> None:
        self._us.append(seconds * 1e6)
        self.steps += 1

    def percentiles(self, *qs: float) -> tuple[float, ...]:
        """Several percentiles from one sort: sorting the window is most of their cost
        (every plug-in reports p50 and p99 once a second)."""
        if not self._us:
            return (float("nan"),) * len(qs)
        ordered = sorted(self._us)
        last = len(ordered) - 1
        return tuple(ordered[min(last, int(q * len(ordered)))] for q in qs)


def _nothing(payer: object = None) -> tuple[float | None, float]:
    return None, 0.0


def _signal_pipe() -> int:
    """The read end of a pipe Python writes a byte to whenever a signal arrives."""
    read_fd, write_fd = os.pipe()
    os.set_blocking(read_fd, False)
    os.set_blocking(write_fd, False)
    signal.set_wakeup_fd(write_fd, warn_on_full_buffer=False)
    return read_fd


class PluginHost:
    """Runs one plug-in instance until stopped.

    ``stop_fd``: the plug-in's stop descriptor when it shares its process with others
    (``composed_host``: one per plug-in, written when that one is to stop); a process of
    its own makes it from its signals. ``restarts``: how often its host restarted it there;
    ``stats``: where its counters go then.
    """

    def __init__(
        self,
        spec: dict[str, Any],
        stop_fd: int | None = None,
        restarts: int = 0,
        stats: Writer[PluginStats] | None = None,
        node: iox2.Node | None = None,
    ) -> None:
        self.spec = spec
        self.stopping = False
        self.composed = stop_fd is not None
        self.restarts = restarts
        self.failed = False
        # The thread that runs this plug-in (its own, or its process's) and the CPU time of
        # its steps run on another thread (a composed process's chain), minus what the
        # steps of others took on this one: its own share of the process's CPU.
        self._cpu_clock = time.pthread_getcpuclockid(threading.get_ident())
        self.cpu_moved_s = 0.0
        self._cpu_mark = (self._cpu_s(), time.monotonic())
        # Run after each step on this plug-in's thread (the composed host's chain), given the
        # host whose thread it is when that is another's; it gives the thread's CPU time when
        # it ended if it read it last (None: it did not) and the CPU its followers took.
        self.after_step: Callable[..., tuple[float | None, float]] = _nothing
        # Set once ``init`` has returned or raised (a composed process starts the rest of
        # its plug-ins after its flight path's).
        self.initialised = threading.Event()
        self.bus = BusNode(spec["namespace"], spec["name"], node)
        self.timer = StepTimer()
        # A composed plug-in's host gives a writer that outlives this instance: the counters
        # of one that failed at once must not vanish with its bus node, unread.
        self.stats = stats or self.bus.writer("system/plugin_stats")
        self.clock = self._clock(spec["vehicle"].get("clock", "monotonic"))
        self.ctx = PluginContext(
            name=spec["name"],
            settings=spec["settings"],
            log=logging.getLogger(f"plugin.{spec['name']}"),
            bus=self.bus,
            clock=self.clock,
            vehicle=spec["vehicle"],
            param_decls=tuple(ParamDecl(**d) for d in spec.get("param_decls", [])),
            plugins=spec.get("plugins", {}),
            stop_fd=_signal_pipe() if stop_fd is None else stop_fd,
            supervisor_pid=os.getppid(),  # adopted by the supervisor before the host starts
        )

    def _cpu_s(self) -> float:
        return time.clock_gettime(self._cpu_clock) + self.cpu_moved_s

    def _clock(self, kind: str) -> VehicleClock:
        if kind == "sim":
            return SimulationClock(self.bus.latest_reader("sim/clock"))
        return MonotonicClock()

    def request_stop(self, signum: int, _frame: object) -> None:
        self.stopping = True

    def publish_stats(self, wake: bool = False) -> None:
        """The counters, for the health table; ``wake``: the supervisor puts them in at
        once (the first after ``init``: the link holds commands until then)."""
        msg = PluginStats(t_us=self.clock.now_us(), pid=os.getpid(), steps=self.timer.steps)
        msg.name = self.spec["name"].encode()[: NAME_LEN - 1]
        health = self.ctx.health
        msg.frames_ok, msg.frames_bad = health.frames_ok, health.frames_bad
        # The plug-in's own losses (bytes, frames) plus its bus readers' overflows, added
        # here only: a plug-in must not add its readers' losses to health.dropped itself.
        msg.dropped = health.dropped + self.bus.total_lost()
        msg.refused, msg.bytes_in = health.refused, health.bytes_in
        msg.step_p50_us, msg.step_p99_us = self.timer.percentiles(0.5, 0.99)
        if self.composed:
            # The process's CPU is shared: this plug-in's share is its own thread's.
            cpu, wall = self._cpu_s(), time.monotonic()
            msg.cpu_pct = 100 * (cpu - self._cpu_mark[0]) / max(wall - self._cpu_mark[1], 1e-3)
            self._cpu_mark = (cpu, wall)
            msg.restarts = self.restarts + int(self.failed)
            msg.state = PluginState.BACKOFF if self.failed else PluginState.RUNNING
        self.stats.publish(msg, wake=wake)
        health.reported_us = msg.t_us

    def start(self, plugin: Plugin) -> bool:
        """``init``, then the first counters; False (counters said, for a composed one) when
        ``init`` raised."""
        self.plugin = plugin
        try:
            plugin.init(self.ctx)
        except Exception:
            log.exception("%s: init failed", self.spec["name"])
            self.failed = True
            if self.composed:  # its row says BACKOFF; a process of its own just dies
                self.publish_stats()
            return False
        finally:
            self.initialised.set()
        # Up: the health table has the new process's own counters before its first step,
        # which waits for its device (a silent one: the read timeout, a second).
        self.publish_stats(wake=True)
        self._next_stats = self._next_connections = time.monotonic()
        return True

    def step_once(self) -> None:
        """One ``step()``, timed, then what falls due: late readers handed this plug-in's
        Latest values, its counters published. Raises what the step raised."""
        started, idle_before = time.perf_counter(), self.bus.idle.seconds
        self.plugin.step()
        # Busy time only: the wait for input is not the plug-in's cost.
        idle = self.bus.idle.seconds - idle_before
        self.timer.add(time.perf_counter() - started - idle)
        if (now := time.monotonic()) >= self._next_connections:
            self.bus.update_connections()
            self._next_connections = now + CONNECTIONS_PERIOD_S
        if now >= self._next_stats:
            self.publish_stats()
            self._next_stats = time.monotonic() + STATS_PERIOD_S

    def finish(self) -> None:
        """``close``, then the last counters."""
        try:
            self.plugin.close()
        except Exception:
            log.exception("%s: close failed", self.spec["name"])
        self.publish_stats()

    def run(self, plugin: Plugin) -> int:
        """Init, steps until stopped, close; the exit status."""
        if not self.start(plugin):
            return EXIT_INIT_FAILED
        code = 0
        try:
            while not self.stopping:
                self.step_once()
                self.after_step()
        except Exception:
            log.exception("%s: step failed", self.spec["name"])
            code = EXIT_STEP_FAILED
            self.failed = True
        finally:
            self.finish()
        return code


def main(spec: dict[str, Any]) -> int:
    """Run the one plug-in of ``spec`` until SIGTERM/SIGINT; the process's exit status
    (started by ``host_main``)."""
    logging.basicConfig(
        level=spec.get("log_level", "INFO"),
        format=f"%(asctime)s {spec['name']}[%(process)d] %(levelname)s %(message)s",
    )
    die_with_parent()
    apply_priority(spec["name"], spec.get("nice", 0), spec["vehicle"])
    host = PluginHost(spec)
    signal.signal(signal.SIGTERM, host.request_stop)
    signal.signal(signal.SIGINT, host.request_stop)
    try:
        plugin = load(spec["kind"])()
        return run_profiled(spec["name"], lambda: host.run(plugin))
    finally:
        host.bus.close()
