"""An OS process that hosts several plug-ins (``process = "NAME"`` in the config).

Each hosted plug-in runs on a thread of its own, in the loop a process of its own runs
(``PluginHost``: init, step until stopped, close, counters on ``system/plugin_stats``), on
a bus node of its own. Threads, not one executor waiting on every plug-in's trigger,
because the contract's ``step()`` blocks on the plug-in's own inputs (a bus wait, a device
read) and a plug-in's code must not know whether it is composed; the waits release the
interpreter lock, so a thread asleep costs nothing and the one woken runs at once
(``docs/dev/process_model.md`` says more).

A plug-in that raises is closed, its bus node released, and started again on its thread
with the back-off the supervisor gives a process (at once, then 0.1 s doubling to 5 s,
afresh after 10 s of running), while the others keep running; its restarts and state go
in its counters. SIGTERM/SIGINT stop every plug-in: each has its own stop descriptor,
written then, which its device waits watch (``PluginContext.stop_fd``), and a bus wait
ends within its timeout.
"""

from __future__ import annotations

import functools
import logging
import os
import signal
import threading
import time
from typing import TYPE_CHECKING, Any

from companion.bus.node import BusNode, new_node
from companion.bus.patterns import Writer
from companion.exec_control.backoff import MAX_BACKOFF_S, SECOND_BACKOFF_S, STABLE_AFTER_S
from companion.exec_control.chain import ChainLink, chain_links, run_followers
from companion.exec_control.composition import flight_members
from companion.exec_control.plugin_host import (
    EXIT_INIT_FAILED,
    EXIT_STEP_FAILED,
    PluginHost,
    _signal_pipe,
    set_name,
)
from companion.exec_control.priority import apply_priority
from companion.exec_control.profiling import run_profiled
from companion.exec_control.registry import load
from companion.fd_wait import drain, wait_readable
from companion.messages import PluginStats

if TYPE_CHECKING:
    import iceoryx2 as iox2

# How long the flight path's plug-ins may take to init before the others start anyway.
PATH_FIRST_S = 0.5
JOIN_GRACE_S = 1.0  # the supervisor kills the process 1.2 s after its SIGTERM
# A change of the health table's flight state wakes the process; this is a second look.
FLIGHT_LOOK_S = 1.0

log = logging.getLogger("companion.composed_host")


class Member:
    """One hosted plug-in: its thread, restarted in place when the plug-in fails."""

    def __init__(
        self,
        spec: dict[str, Any],
        link: ChainLink | None = None,
        followers: list[ChainLink] | None = None,
        node: iox2.Node | None = None,
    ) -> None:
        self.spec = spec
        self.node = node  # the process's bus node, each instance's channels opened on it
        self.link = link  # run by the plug-in that publishes its trigger (``chain``)
        # Chained to this one: run on this thread after its steps.
        if followers is None:
            followers = link.followers if link else []
        self.followers = followers
        self.name: str = spec["name"]
        self._stop_r, self._stop_w = os.pipe()
        # Non-blocking, as a process's own signal pipe is: a device read that finds it
        # readable drains it (``fd_wait.drain`` reads until empty), and on a blocking pipe
        # that read waited for ever: every serial sensor's thread hung at a stop, and the
        # process ended a second later with their ports never closed.
        os.set_blocking(self._stop_r, False)
        self.stopping = False
        self.restarts = 0
        self.host: PluginHost | None = None
        self.initialised = threading.Event()  # its first instance's init returned or raised
        self.thread = threading.Thread(target=self.run, name=self.name, daemon=True)

    def renewed(self) -> Member:
        """A fresh member for the same plug-in (a thread starts once), its restarts and
        its place in the chain kept."""
        member = Member(self.spec, self.link, self.followers, self.node)
        member.restarts = self.restarts
        return member

    def stop(self) -> None:
        """Ask the plug-in to stop after its current step: its stop descriptor turns
        readable, ending any wait on it, until a device read drains it; the stop itself
        is the flag its host looks at after each step."""
        self.stopping = True
        if self.host is not None:
            self.host.stopping = True
        os.write(self._stop_w, b"s")

    def run(self) -> None:
        """The thread: run the plug-in, and again after each failure, until stopped."""
        apply_priority(self.name, self.spec.get("nice", 0), self.spec["vehicle"])  # its own
        set_name(self.name)  # its thread's, as top -H shows it
        with BusNode(self.spec["namespace"], f"{self.name}_stats", self.node) as node:
            self.loop(node.writer("system/plugin_stats"))

    def loop(self, stats: Writer[PluginStats]) -> None:
        backoff_s = 0.0
        while not self.stopping:
            started = time.monotonic()
            # COMPANION_PROFILE: one profile per thread, a chained plug-in's steps in its
            # producer's (cProfile follows only the thread that enabled it).
            code = run_profiled(self.name, lambda: self.run_once(stats), per_thread=True)
            if self.stopping:
                break
            if time.monotonic() - started >= STABLE_AFTER_S:
                backoff_s = 0.0
            self.restarts += 1
            log.warning("%s failed (status %d); restart in %.1f s", self.name, code, backoff_s)
            # Waits on the stop descriptor: a stop during the back-off ends it.
            wait_readable([self._stop_r], backoff_s)
            backoff_s = min(max(backoff_s * 2, SECOND_BACKOFF_S), MAX_BACKOFF_S)

    def run_once(self, stats: Writer[PluginStats]) -> int:
        """Init, steps and close of one instance on a fresh bus node; its exit status."""
        try:
            host = PluginHost(self.spec, self._stop_r, self.restarts, stats, self.node)
        except Exception:
            log.exception("%s: no bus node", self.name)
            self.initialised.set()
            return EXIT_INIT_FAILED
        self.host = host
        host.initialised = self.initialised
        host.stopping = self.stopping  # a stop that came while it was being made
        if self.followers:
            # A partial, not a lambda: one Python frame less at every step of the producer.
            host.after_step = functools.partial(run_followers, self.followers, host)
        try:
            if self.link is not None:
                return self.run_chained(host, self.link)
            return host.run(load(self.spec["kind"])())
        except BaseException:  # a plug-in's SystemExit ends its thread, not the others
            log.exception("%s failed", self.name)
            return EXIT_INIT_FAILED
        finally:
            self.initialised.set()  # also when it failed before its init
            self.host = None
            host.bus.close()

    def run_chained(self, host: PluginHost, link: ChainLink) -> int:
        """Init, steps (on the producer's thread, or here while it delivers nothing),
        close; the exit status."""
        if not host.start(load(self.spec["kind"])()):
            return EXIT_INIT_FAILED
        code = 0
        try:
            if not link.serve(host, self._stop_r):
                code = EXIT_STEP_FAILED  # raised on the producer's thread, said there
        except Exception:
            log.exception("%s: step failed", self.name)
            code = EXIT_STEP_FAILED
        finally:
            host.failed = code != 0
            host.finish()
        return code


_PROCESS_KEYS = ("members", "name", "kind", "group", "flight_running")


def member_specs(spec: dict[str, Any]) -> list[dict[str, Any]]:
    """Each hosted plug-in's spec as a process of its own would get it."""
    shared = {k: v for k, v in spec.items() if k not in _PROCESS_KEYS}
    tables = {k: shared.pop(k) for k in ("param_decls", "plugins") if k in shared}
    out = []
    for member in spec["members"]:
        wants = load(member["kind"]).wants_vehicle_tables
        out.append({**shared, **(tables if wants else {}), **member})
    return out


class FlightSwitch:
    """The flight plug-ins of a core process: started while the flight group runs (the
    supervisor's ``system/health`` says so; ``flight_running`` of the spec when the process
    started), stopped when it stops. Each start is a fresh thread and instance, with the
    restarts counted so far and its place in the chain kept."""

    def __init__(self, members: list[Member]) -> None:
        self.members = members
        self.running = False

    def set(self, running: bool) -> None:
        if running == self.running or not self.members:
            return
        self.running = running
        if running:
            self.members = [m.renewed() for m in self.members]
            for member in self.members:
                member.thread.start()
        else:
            stop_all(self.members)
        log.info("flight plug-ins %s", "started" if running else "stopped")


def await_init(members: list[Member], timeout_s: float) -> None:
    """Wait until each member's init has returned or raised, ``timeout_s`` at most."""
    deadline = time.monotonic() + timeout_s
    for member in members:
        member.initialised.wait(max(0.0, deadline - time.monotonic()))


def stop_all(members: list[Member]) -> None:
    """Stop the members' plug-ins and wait (within the supervisor's grace) for them."""
    for member in members:
        member.stop()
    deadline = time.monotonic() + JOIN_GRACE_S
    for member in members:
        member.thread.join(max(0.0, deadline - time.monotonic()))


def wire(specs: list[dict[str, Any]], node: iox2.Node | None = None) -> list[Member]:
    """A member for each spec, each chained plug-in among its producer's followers, all
    on the bus ``node`` (None: each instance a node of its own)."""
    links = chain_links(specs)
    members = [Member(s, links[s["name"]][1] if s["name"] in links else None, node=node)
               for s in specs]  # fmt: skip
    by_name = {m.name: m for m in members}
    for name, (producer, link) in links.items():
        by_name[producer].followers.append(link)
        log.info("%s runs after %s on its wake-up", name, producer)
    return members


def main(spec: dict[str, Any]) -> int:
    """Run the hosted plug-ins until SIGTERM/SIGINT; the process's exit status."""
    logging.basicConfig(
        level=spec.get("log_level", "INFO"),
        format=f"%(asctime)s {spec['name']}[%(process)d] %(threadName)s %(levelname)s %(message)s",
    )
    from companion.exec_control.plugin_host import die_with_parent

    die_with_parent()
    stopping = threading.Event()
    wake = _signal_pipe()  # readable once a signal has come
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: stopping.set())
    specs = member_specs(spec)
    # One iceoryx2 node for every plug-in here: making one costs milliseconds, and a
    # process restarted in the air made two dozen of them, each cleaning up after the
    # dead ones, under the interpreter's lock before its servos answered again. The
    # process is the unit that dies; a plug-in restarted alone closes its own ports.
    node = new_node(spec["namespace"], spec["name"])
    members = wire(specs, node)
    in_flight = set(flight_members(specs))
    always = [m for m in members if m.name not in in_flight]
    flight = FlightSwitch([m for m in members if m.name in in_flight])
    # The flight path first, and the others once its plug-ins are up: a process killed in
    # the air otherwise inits them all at once under one interpreter lock, and its servos
    # answered again only after every other plug-in's init (0.4-0.5 s after the kill).
    path = [m for m in always if m.link is not None or m.followers]
    for member in path:
        member.thread.start()
    flight.set(bool(spec.get("flight_running")))
    await_init(path + (flight.members if flight.running else []), PATH_FIRST_S)
    for member in always:
        if member not in path:
            member.thread.start()
    # The main thread sleeps until a signal (the plug-ins' threads do the work), or a
    # change of the flight group when it hosts flight plug-ins.
    if in_flight:
        follow_flight_group(spec, flight, stopping, wake, node)
    while not stopping.is_set():
        wait_readable([wake], None)
        drain(wake)
    stop_all(always + (flight.members if flight.running else []))
    return 0


def follow_flight_group(
    spec: dict[str, Any],
    flight: FlightSwitch,
    stopping: threading.Event,
    wake: int,
    process_node: iox2.Node | None = None,
) -> None:
    """Start and stop the flight plug-ins as the supervisor's table says, until a signal."""
    with BusNode(spec["namespace"], f"{spec['name']}_flight", process_node) as node:
        health = node.latest_reader("system/health")
        waiter = node.waiter([health])
        while not stopping.is_set():
            _, ready = waiter.wait_with_fds(FLIGHT_LOOK_S, [wake], fds_key=wake)  # kept
            if ready:
                drain(wake)
            table = health.get()
            if table is not None:
                flight.set(bool(table.flight_running))
        waiter.close()
