"""Plug-ins of one process run one after another on a single wake-up (a work queue).

A plug-in that declares a ``trigger`` (``Plugin.trigger``: the navigator's IMU, the
controller's navigation state, the servos' commands) and shares its process with the one
plug-in that publishes that channel is *chained* to it: after each step in which the
producer published the trigger, the producer's thread runs the follower's step at once.
The follower's wait then finds the sample already there and returns without sleeping, so
the sample costs the process one wake-up however many plug-ins it passes through, as a
PX4 work queue runs the modules scheduled on it. A wake-up of a Python thread costs far
more than the bus work it starts (``benchmarks/wake_floor.py``).

The follower keeps a thread of its own, which does three things the chain cannot:
- it runs ``init`` and ``close`` (and restarts the plug-in after a failure, with the
  composed host's back-off);
- while the producer has not run it for its ``trigger_timeout_s`` (the producer stopped
  publishing, or has not started), it steps the plug-in itself, as a plug-in of its own
  would, so its timeouts (the servos' safe positions when commands stop) still act;
- it is the thread the follower's failures are handled on: a step that raises on the
  producer's thread is logged and hands the plug-in back to its own thread, which closes
  and restarts it; the producer goes on.

A lock keeps the two threads from stepping the plug-in at once. The producer never waits
for it: a follower busy stepping itself (in its own wait) receives the sample there.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from companion.exec_control.registry import load
from companion.fd_wait import wait_readable

if TYPE_CHECKING:
    from companion.bus.patterns import Reader
    from companion.exec_control.plugin_host import PluginHost
    from companion.plugin import Plugin

log = logging.getLogger("companion.chain")


class ChainLink:
    """A chained plug-in: what its producer's thread needs to run its step."""

    def __init__(self, name: str, trigger: str, idle_s: float) -> None:
        self.name = name
        self.trigger = trigger
        # Not run by its producer for this long (the plug-in's ``trigger_timeout_s``), it
        # steps itself, and so waits on its own inputs again.
        self.idle_s = idle_s
        self.followers: list[ChainLink] = []  # chained to this one in turn
        self.host: PluginHost | None = None  # set while its plug-in is up
        self.failed = False
        self._lock = threading.Lock()
        self._last_run = -float("inf")  # when the producer last ran it (or tried to)
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        self._reader: Reader[Any] | None = None
        self._reader_host: PluginHost | None = None

    def _trigger_reader(self, host: PluginHost) -> Reader[Any] | None:
        """The plug-in's reader of its trigger (looked up once per instance)."""
        if self._reader_host is not host:
            self._reader_host, self._reader = host, host.bus.reader_of(self.trigger)
        return self._reader

    def run_after(self, payer: PluginHost) -> tuple[float | None, float]:
        """On ``payer``'s thread (the plug-in whose thread it is), after the producer's step:
        this plug-in's step, if a sample of its trigger waits for it (its wait would then
        return at once: a step run without one would sleep on the producer's thread) and it
        is not busy on its own thread. The thread's CPU time when it ended (None: it did not
        run) and the CPU time it and its own followers took."""
        host = self.host
        if host is None:
            return None, 0.0
        reader = self._reader if self._reader_host is host else self._trigger_reader(host)
        if reader is None or not reader.has_samples():
            return None, 0.0
        self._last_run = time.monotonic()  # the producer delivers: no step of its own
        if not self._lock.acquire(blocking=False):
            return None, 0.0  # busy in its own step: its own wait takes the sample
        # The CPU of this step is moved from the thread's own plug-in's row to this one, and
        # each follower moves its own share from that same row: every row holds its own
        # steps at every moment (moved through the producer, a producer's row read between
        # its follower's move and its own showed minus the follower's step, then plus it:
        # 43 % for a relay a second after a long one). A last follower's reading at its end
        # is this one's end too (a clock read is a system call).
        cpu_before, cpu_after, followers = time.thread_time(), None, 0.0
        try:
            if self._step_locked(host):
                cpu_after, followers = host.after_step(payer)  # its own followers
        finally:
            if cpu_after is None:
                cpu_after = time.thread_time()
            took = cpu_after - cpu_before
            own = took - followers
            host.cpu_moved_s += own
            payer.cpu_moved_s -= own
        return cpu_after, took

    def _step_locked(self, host: PluginHost) -> bool:
        """One step under the lock ``run_after`` took; whether it ran and succeeded.

        Only when the producer notified: a sample published without waking its readers
        (the IMU's between two navigation states) would wake a plug-in of its own process
        neither, and goes with the next one. Taken under the lock: the plug-in's own
        thread is then not asleep on the same notifications.
        """
        try:
            reader = self._reader
            if (
                self.host is not host
                or self.failed
                or reader is None
                or not reader.take_notifications()
            ):
                return False
            host.step_once()
            return True
        except (Exception, SystemExit):
            log.exception("%s: step failed", self.name)
            self.failed = True
            os.write(self._wake_w, b"f")  # its own thread closes and restarts it
            return False
        finally:
            self._lock.release()

    def serve(self, host: PluginHost, stop_fd: int) -> bool:
        """On the plug-in's own thread, after its ``init``: step it whenever the producer
        has not for ``idle_s``, until stopped or a chained step failed (False then)."""
        self.failed = False
        self.host = host
        try:
            while not host.stopping and not self.failed:
                left = self._last_run + self.idle_s - time.monotonic()
                if left > 0:
                    ready = wait_readable([stop_fd, self._wake_r], left)
                    if self._wake_r in ready:
                        os.read(self._wake_r, 64)
                    continue
                with self._lock:
                    if host.stopping or self.failed:
                        break
                    host.step_once()
                host.after_step()  # its own followers
        finally:
            with self._lock:  # a step in progress on the producer's thread ends first
                self.host = None
        return not self.failed


def run_followers(
    followers: Sequence[ChainLink], producer: PluginHost, payer: PluginHost | None = None
) -> tuple[float | None, float]:
    """Run each follower that has a sample of its trigger waiting, after ``producer``'s step,
    on ``payer``'s thread (the producer's own when None); the thread's CPU time when the
    last one ended (None: the last did not run) and the CPU time they took."""
    payer = producer if payer is None else payer
    cpu_after, took = None, 0.0
    for link in followers:
        cpu_after, link_took = link.run_after(payer)
        took += link_took
    return cpu_after, took


def chain_links(members: Sequence[dict[str, Any]]) -> dict[str, tuple[str, ChainLink]]:
    """For each plug-in chained to another of these specs: its producer's name and its
    link. A plug-in is chained when exactly one other plug-in here publishes its trigger;
    a cycle is left unchained (one of its plug-ins must wake on its own)."""
    outputs = {m["name"]: set(load(m["kind"]).ports(m["settings"]).outputs) for m in members}
    producer_of: dict[str, str] = {}
    for m in members:
        trigger = load(m["kind"]).trigger
        if trigger is None:
            continue
        producers = [n for n, outs in outputs.items() if trigger in outs and n != m["name"]]
        if len(producers) == 1:
            producer_of[m["name"]] = producers[0]
    for name in list(producer_of):
        seen, at = {name}, producer_of[name]
        while at in producer_of and at not in seen:
            seen.add(at)
            at = producer_of[at]
        if at in seen:  # back at a plug-in already on the way: a cycle
            producer_of.pop(name)
    kinds = {m["name"]: load(m["kind"]) for m in members}
    return {name: (producer, _link(name, kinds[name])) for name, producer in producer_of.items()}


def _link(name: str, kind: type[Plugin]) -> ChainLink:
    assert kind.trigger is not None
    return ChainLink(name, kind.trigger, kind.trigger_timeout_s)
