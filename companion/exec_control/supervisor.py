"""The execution-control process: run the config's plug-ins and keep them running.

Starts the ``core`` group at once and the ``flight`` group on START (arm), stops the
flight group on STOP (disarm), restarts any plug-in that dies, publishes the health table
on ``system/health`` once a second, and stops everything on SIGINT/SIGTERM.
"""

from __future__ import annotations

import logging
import os
import signal
import time
from dataclasses import asdict

from companion.bus.clock import MonotonicClock, SimulationClock, VehicleClock
from companion.bus.namespace import SUPERVISOR_NODE, cleanup_namespace, in_use_refusal
from companion.bus.node import BusNode
from companion.bus.patterns import Reader, Writer
from companion.exec_control.child import FIRST_BACKOFF_S, Child
from companion.exec_control.composed_child import ComposedChild
from companion.exec_control.composition import processes, start_rank
from companion.exec_control.config import VehicleConfig
from companion.exec_control.priority import note_refused_raises
from companion.exec_control.registry import load
from companion.exec_control.zygote import READY_TIMEOUT_S, ForkServer, become_subreaper
from companion.messages import (
    CommandAck,
    CommandId,
    CommandResult,
    PluginStats,
    SystemHealth,
    VehicleCommand,
)

log = logging.getLogger(__name__)

HEALTH_PERIOD_S = 1.0
EXIT_BUS_IN_USE = 3  # another vehicle runs on this bus namespace: nothing was started
FORKER_BACKOFF_S = 1.0
# SIGCHLD wakes the loop when a plug-in dies; this is only the backstop (a signal that
# reached another thread). Nothing else wakes an idle supervisor but the health table.
REAP_PERIOD_S = 1.0
STOP_GRACE_S = 1.2  # SIGTERM, then SIGKILL: total shutdown stays under 2 s


class Supervisor:
    """Runs one vehicle config until a stop signal."""

    def __init__(
        self, cfg: VehicleConfig, log_level: str = "INFO", forker: ForkServer | None = None
    ) -> None:
        self.cfg = cfg
        base = {"namespace": cfg.namespace, "vehicle": cfg.vehicle, "log_level": log_level}
        tables = {
            "param_decls": [asdict(d) for spec in cfg.plugins for d in spec.params],
            "plugins": {spec.kind: spec.settings for spec in cfg.plugins},
        }
        self.children: list[Child] = []
        self.rank = start_rank(cfg.plugins)
        for process, specs in processes(cfg.plugins):
            wants = any(load(spec.kind).wants_vehicle_tables for spec in specs)
            args = {**base, **tables} if wants else base
            if process:
                self.children.append(ComposedChild(process, specs, args))
            else:
                self.children.append(Child(specs[0], args))
        # A fork server started early (while the simulator loads) may be handed in.
        self.forker = forker or ForkServer(sorted({s.kind for s in cfg.plugins}), log_level)
        self.next_forker_at = 0.0
        self.flight_running = False
        self._health_shape: tuple[object, ...] = ()  # of the last table that woke its readers
        self.reason = ""  # why the last command was refused, for its ack
        self.stopping = False
        self.clock: VehicleClock = MonotonicClock()
        self.until: float | None = None

    def request_stop(self, signum: int, _frame: object) -> None:
        log.info("received %s: stopping", signal.Signals(signum).name)
        self.stopping = True

    def group(self, name: str) -> list[Child]:
        return [c for c in self.children if c.spec.group == name]

    def start_group(self, name: str) -> None:
        # The flight chain and what it needs first: a restart in the air is back sooner.
        for child in sorted(self.group(name), key=self._rank):
            if not child.wanted:
                child.wanted = True
                child.backoff_s = FIRST_BACKOFF_S
                if child.proc is None:
                    child.start()

    def _rank(self, child: Child) -> int:
        members = getattr(child, "members", [child.spec])
        return min(self.rank.get(m.name, 1) for m in members)

    def stop_children(self, children: list[Child]) -> None:
        """SIGTERM, wait for a clean exit, SIGKILL what is left."""
        for child in children:
            child.signal_stop()
        deadline = time.monotonic() + STOP_GRACE_S
        for child in children:
            if not child.wait_stopped(deadline):
                log.warning("%s did not stop in time: killing it", child.spec.name)
                child.kill()
                child.wait_stopped(time.monotonic() + 0.5)

    def prearm_problem(self) -> str:
        """The first reason a flight plug-in gives for not arming ("" when none)."""
        for spec in (s for s in self.cfg.plugins if s.group == "flight"):
            for reason in load(spec.kind).prearm(spec.settings, self.cfg.vehicle):
                return f"PreArm: {reason}"
        return ""

    def handle_command(self, cmd: VehicleCommand) -> CommandResult | None:
        """Act on the commands that belong to execution control; None for the others."""
        kind = cmd.command
        self.reason = ""
        if kind == CommandId.START:
            if cmd.param[1] >= 0.5 and not self.flight_running:  # the link asks for checks
                self.reason = self.prearm_problem()
                if self.reason:
                    log.warning("arming refused: %s", self.reason)
                    return CommandResult.DENIED
            self.start_group("flight")
            self._flight(True)
        elif kind == CommandId.STOP:
            self.stop_children(self.group("flight"))
            self._flight(False)
        elif kind == CommandId.RESTART_PLUGINS:
            wanted = [c for c in self.children if c.wanted]
            self.stop_children(wanted)
            for child in wanted:
                child.wanted = True
                child.restarts += 1
                child.start()
        else:
            return None
        return CommandResult.ACCEPTED

    def _flight(self, running: bool) -> None:
        self.flight_running = running
        for child in self.children:
            child.flight_changed(running)

    def publish_health(self, writer: Writer[SystemHealth]) -> None:
        msg = SystemHealth(t_us=self.clock.now_us(), supervisor_pid=os.getpid())
        msg.flight_running = int(self.flight_running)
        rows = []
        for child in self.children:
            child.sample_usage()
            rows += child.health_rows()
        msg.count = len(rows)
        for i, row in enumerate(rows):
            msg.plugins[i] = row
        # Arming, a plug-in starting, dying or restarting wakes the readers that wait on
        # the table (commander, link, logger); the counters alone, once a second, do not.
        shape = (msg.flight_running, *((r.state, r.pid, r.restarts) for r in msg.rows()))
        writer.publish(msg, wake=shape != self._health_shape)
        self._health_shape = shape

    def absorb_stats(self, stats: Reader[PluginStats]) -> bool:
        """Every plug-in's counters kept; True when one reported for the first time since
        it started (the table goes out at once)."""
        first = False
        for msg in stats.drain():
            for child in self.children:
                if child.absorb(msg):
                    first |= child.first_report
                    break
        return first

    def supervise_forker(self) -> None:
        """Restart a dead fork server (plug-ins are spawned meanwhile, and never lost)."""
        if self.children[0].forker is None if self.children else True:
            return  # no sub-reaper here: every plug-in is spawned
        now = time.monotonic()
        if self.forker.reap():
            self.next_forker_at = now + min(FORKER_BACKOFF_S * self.forker.starts, 30.0)
        if self.forker.proc is None and now >= self.next_forker_at:
            self.forker.start()

    def restart_dead(self) -> None:
        self.supervise_forker()
        now = time.monotonic()
        for child in self.children:
            child.reap(now)
            if child.restart_due(now):
                child.restarts += 1
                child.start()

    def next_timeout(self, next_health: float) -> float:
        now = time.monotonic()
        due = [next_health, now + REAP_PERIOD_S]
        due += [c.next_start_at for c in self.children if c.wanted and c.proc is None]
        return max(0.0, min(due) - now)

    def run(self, duration_s: float | None = None) -> int:
        """Supervise until SIGINT/SIGTERM (or ``duration_s``); return the exit status."""
        self.until = None if duration_s is None else time.monotonic() + duration_s
        signal.signal(signal.SIGTERM, self.request_stop)
        signal.signal(signal.SIGINT, self.request_stop)
        # A plug-in's death interrupts the wait below, so its restart is not left to a timer.
        signal.signal(signal.SIGCHLD, lambda *_: None)
        if become_subreaper():  # forked plug-ins need an adopting parent
            for child in self.children:
                child.forker = self.forker
            if self.forker.proc is None:
                self.forker.start()
        # Only once the fork server is forked: this process's first use of iceoryx2, made
        # before, is inherited by every forked plug-in, and a restarted one then found its
        # killed predecessors' subscriptions still held (ExceedsMaxSupportedSubscribers).
        if (refusal := in_use_refusal(self.cfg.namespace)) is not None:
            log.error("%s", refusal)
            self.forker.stop()
            return EXIT_BUS_IN_USE
        cleanup_namespace(self.cfg.namespace)  # leftovers of a crashed earlier run
        note_refused_raises(self.cfg.plugins)
        bus = BusNode(self.cfg.namespace, SUPERVISOR_NODE)
        try:
            self._loop(bus)
        finally:
            self.stop_children([c for c in self.children if c.spec.group == "flight"])
            self.stop_children(self.children)
            self.forker.stop()
            signal.signal(signal.SIGCHLD, signal.SIG_DFL)
            bus.close()
            cleanup_namespace(self.cfg.namespace)
        log.info("stopped")
        return 0

    def _loop(self, bus: BusNode) -> None:
        if self.cfg.vehicle.get("clock") == "sim":
            # The health table and the acks share the plug-ins' time base: one timeline
            # in the flight log, not sim time beside the host's uptime.
            self.clock = SimulationClock(bus.latest_reader("sim/clock"))
        health = bus.writer("system/health")
        acks = bus.writer("link/command_acks")
        commands = bus.queue_reader("link/commands")
        stats = bus.queue_reader("system/plugin_stats")
        # Commands wake it, and a plug-in's first counters (it is up: ``commands.held``);
        # the others (each plug-in's once a second) wait for the table they go into.
        waiter = bus.waiter([commands, stats], triggers=[commands, stats])
        if self.forker.proc is not None:
            if self.forker.wait_ready(READY_TIMEOUT_S):
                log.info("fork server ready")
            else:
                log.warning("fork server not ready: spawning plug-ins until it is")
        self.start_group("core")
        next_health = time.monotonic()
        while not self.stopping:
            waiter.wait(self.next_timeout(next_health))
            if self.until is not None and time.monotonic() >= self.until:
                break
            for cmd in commands.drain():
                result = self.handle_command(cmd)
                if result is not None:
                    # The new arm state is out before the ack: whoever acts on the ack
                    # (the commander setting home, a ground station) finds it already.
                    self.publish_health(health)
                    next_health = time.monotonic() + HEALTH_PERIOD_S
                    acks.publish(self._ack(cmd, result))
            if self.absorb_stats(stats):
                next_health = time.monotonic()
            self.restart_dead()
            bus.update_connections()
            if time.monotonic() >= next_health:
                self.publish_health(health)
                next_health = time.monotonic() + HEALTH_PERIOD_S
        waiter.close()

    def _ack(self, cmd: VehicleCommand, result: CommandResult) -> CommandAck:
        # The reason whole: the field fits a PreArm text.
        return CommandAck.answer(cmd, self.clock.now_us(), b"exec_control", result, self.reason)
