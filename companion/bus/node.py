"""One process's connection to the bus: opens channels by their registered names."""

from __future__ import annotations

import logging
import os
from collections.abc import Sequence
from typing import Any

import iceoryx2 as iox2

from companion.bus.namespace import default_namespace, make_config
from companion.bus.patterns import (
    IdleTally,
    LatestReader,
    QueueReader,
    Reader,
    SampleHeader,
    Writer,
    duration,
)
from companion.messages import MAX_PLUGINS, Channel, channel

log = logging.getLogger(__name__)

# Limits are part of a service's identity in iceoryx2: every process must open a
# channel with the same numbers, so they are fixed here rather than per caller.
MAX_PUBLISHERS = 8
MAX_SUBSCRIBERS = 16
MAX_NODES = 2 * MAX_PLUGINS + 8
MAX_NOTIFIERS = MAX_PLUGINS + 8
MAX_LISTENERS = MAX_SUBSCRIBERS + 4


def new_node(namespace: str, name: str = "") -> iox2.Node:
    """An iceoryx2 node of the namespace, named ``name.pid``.

    Making one costs milliseconds (its files in /dev/shm, its monitoring token): a
    process hosting many plug-ins makes one and opens each plug-in's channels on it.
    """
    # Signals belong to the Python process (the plug-in runner and supervisor install
    # their own SIGTERM/SIGINT handlers); iceoryx2 must not swallow them.
    builder = (
        iox2.NodeBuilder.new()
        .config(make_config(namespace))
        .signal_handling_mode(iox2.SignalHandlingMode.Disabled)
    )
    if name:
        builder = builder.name(iox2.NodeName.new(f"{name}.{os.getpid()}"))
    return builder.create(iox2.ServiceType.Ipc)


class BusNode:
    """A process's node on the bus of one namespace.

    >>> bus = BusNode("test")                       # doctest: +SKIP
    >>> imu = bus.writer("sensors/imu")             # doctest: +SKIP
    >>> nav = bus.latest_reader("nav/state")        # doctest: +SKIP
    """

    def __init__(
        self,
        namespace: str | None = None,
        name: str = "",
        node: iox2.Node | None = None,
    ) -> None:
        """``node``: an iceoryx2 node of this namespace to open the channels on, shared
        with other BusNodes of the process and left open by ``close`` (``new_node``);
        else one of its own."""
        self.namespace = namespace or default_namespace()
        self._owns_node = node is None
        self._node = new_node(self.namespace, name) if node is None else node
        self._ports: list[Writer[Any] | Reader[Any]] = []
        self._latest_writers: list[Writer[Any]] = []
        self.idle = IdleTally()

    def _pubsub(self, chan: Channel) -> Any:
        builder = (
            self._node.service_builder(iox2.ServiceName.new(chan.name))
            .publish_subscribe(chan.type)
            .user_header(SampleHeader)
            .max_publishers(MAX_PLUGINS + 8 if chan.many_producers else MAX_PUBLISHERS)
            .max_subscribers(MAX_SUBSCRIBERS)
            .max_nodes(MAX_NODES)
            .enable_safe_overflow(True)
        )
        if chan.pattern == "latest":
            builder = builder.history_size(1).subscriber_max_buffer_size(chan.depth)
        else:
            builder = builder.history_size(0).subscriber_max_buffer_size(chan.depth)
        return builder.open_or_create()

    def _event(self, chan: Channel) -> Any:
        return (
            self._node.service_builder(iox2.ServiceName.new(chan.name))
            .event()
            .max_notifiers(MAX_NOTIFIERS)
            .max_listeners(MAX_LISTENERS)
            .max_nodes(MAX_NODES)
            .open_or_create()
        )

    def writer(self, name: str) -> Writer[Any]:
        """A writer for the registered channel ``name`` (Queue or Latest alike)."""
        chan = channel(name)
        service = self._pubsub(chan)
        pub = service.publisher_builder().create()
        notifier = self._event(chan).notifier_builder().create()
        port: Writer[Any] = Writer(name, pub, notifier, chan.type, service)
        self._ports.append(port)
        if chan.pattern == "latest":
            self._latest_writers.append(port)
        return port

    def reader_of(self, name: str) -> Reader[Any] | None:
        """This node's first reader of channel ``name`` (None: it has none)."""
        for port in self._ports:
            if isinstance(port, Reader) and port.name == name:
                return port
        return None

    def update_connections(self) -> None:
        """Give late readers of this node's Latest channels the last value published."""
        for port in self._latest_writers:
            port.update_connections()

    def queue_reader(self, name: str) -> QueueReader[Any]:
        """A reader of the Queue channel ``name``."""
        chan = channel(name)
        if chan.pattern != "queue":
            raise ValueError(f"channel {name!r} is a Latest channel; use latest_reader()")
        service = self._pubsub(chan)
        sub = service.subscriber_builder().buffer_size(chan.depth).create()
        listener = self._event(chan).listener_builder().create()
        port: QueueReader[Any] = QueueReader(name, chan.type, sub, listener, self.idle, service)
        self._ports.append(port)
        return port

    def latest_reader(self, name: str, keep: int = 1) -> LatestReader[Any]:
        """A reader of the Latest channel ``name``; it holds the newest ``keep`` values
        between reads (at most the channel's depth), for a reader that wants every one."""
        chan = channel(name)
        if chan.pattern != "latest":
            raise ValueError(f"channel {name!r} is a Queue channel; use queue_reader()")
        service = self._pubsub(chan)
        sub = service.subscriber_builder().buffer_size(max(1, min(keep, chan.depth))).create()
        listener = self._event(chan).listener_builder().create()
        port: LatestReader[Any] = LatestReader(name, chan.type, sub, listener, self.idle, service)
        self._ports.append(port)
        return port

    def newest_reader(self, name: str) -> LatestReader[Any]:
        """The newest sample of channel ``name`` of either pattern, as ``latest_reader``
        gives it: of a Queue channel it holds one sample, the older ones being overwritten
        unread (not copied, not counted as lost), for a reader that shows only the newest
        value (the link's telemetry of 100 Hz sensors)."""
        chan = channel(name)
        service = self._pubsub(chan)
        sub = service.subscriber_builder().buffer_size(1).create()
        listener = self._event(chan).listener_builder().create()
        port: LatestReader[Any] = LatestReader(name, chan.type, sub, listener, self.idle, service)
        self._ports.append(port)
        return port

    def reader(self, name: str) -> Reader[Any]:
        """A reader of either pattern, chosen by the channel's registration."""
        if channel(name).pattern == "queue":
            return self.queue_reader(name)
        return self.latest_reader(name)

    def waiter(
        self, readers: Sequence[Reader[Any]], triggers: Sequence[Reader[Any]] | None = None
    ) -> Waiter:
        """A reusable wait over several readers (one iceoryx2 WaitSet); only ``triggers``
        (default: all of them) end the wait."""
        return Waiter(readers, self.idle, triggers)

    def gated_waiter(self, gated: Reader[Any], others: Sequence[Reader[Any]]) -> GatedWaiter:
        """A wait over ``gated`` and ``others`` that ``gated`` ends only when asked."""
        return GatedWaiter(gated, others, self.idle)

    def total_lost(self) -> int:
        """Samples this node's Queue readers lost to overflow, all channels together."""
        return sum(p.lost for p in self._ports if isinstance(p, Reader))

    def close(self) -> None:
        """Release every port and the node."""
        for port in reversed(self._ports):
            try:
                port.close()
            except Exception as exc:  # closing twice, or after iceoryx2 already did
                log.debug("closing %s: %s", port.name, exc)
        self._ports.clear()
        self._latest_writers.clear()
        if self._owns_node:
            del self._node

    def __enter__(self) -> BusNode:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class Waiter:
    """Sleeps until any of several readers (its triggers) has data, or a timeout passes.

    Readers that are not triggers wake nobody: their data waits for the next wake-up (the
    supervisor woken by commands only, the plug-ins' counters read when it wakes anyway),
    and their notifications are cleared then.
    """

    def __init__(
        self,
        readers: Sequence[Reader[Any]],
        idle: IdleTally | None = None,
        triggers: Sequence[Reader[Any]] | None = None,
    ) -> None:
        self.readers = list(readers)
        self.triggers = self.readers if triggers is None else list(triggers)
        self._idle = idle or IdleTally()
        self._guards: list[Any] = []
        self._owners: dict[Any, Reader[Any]] = {}
        self._built: Any = None
        self._fd_guards: list[Any] = []
        self._fd_ids: dict[Any, int] = {}  # an attached descriptor's id, as the WaitSet says
        self._fds_kept: tuple[Any, ...] | None = None  # what the attached ones were, kept

    @property
    def _waitset(self) -> Any:
        """The WaitSet over the triggers, made when first needed: a single trigger waits on
        its own listener and needs one only to wait on descriptors too."""
        if self._built is None:
            self._built = (
                iox2.WaitSetBuilder.new()
                .signal_handling_mode(iox2.SignalHandlingMode.Disabled)
                .create(iox2.ServiceType.Ipc)
            )
            self._guards = [self._built.attach_notification(r.listener) for r in self.triggers]
            # What each attachment's id, as the WaitSet reports it fired, belongs to.
            self._owners = {
                iox2.WaitSetAttachmentId.from_guard(g): r
                for g, r in zip(self._guards, self.triggers, strict=True)
            }
        return self._built

    def wait(self, timeout_s: float) -> list[Reader[Any]]:
        """The readers with data, after sleeping at most ``timeout_s`` for the first."""
        if len(self.triggers) == 1:
            return self._wait_on_one(self.triggers[0], timeout_s)
        return self._settle(self._wait(timeout_s))

    def sleep(self, timeout_s: float) -> None:
        """As :meth:`wait`, for a caller that reads every one of its readers next anyway (the
        navigator, the servo output): without asking each reader whether it holds data, a
        call into iceoryx2 each, at every sample."""
        if len(self.triggers) == 1:
            self.triggers[0].wait_event(timeout_s)
        else:
            self._clear(self._wait(timeout_s))

    def _wait_on_one(self, trigger: Reader[Any], timeout_s: float) -> list[Reader[Any]]:
        """One trigger (the navigator's IMU, the servos' commands): the reader's own wait on
        its listener, which takes every notification it wakes for. The WaitSet's wait and
        its book-keeping cost a third more per wake-up, 100 times a second."""
        trigger.wait_event(timeout_s)
        return [r for r in self.readers if r.has_samples()]

    def wait_with_fds(
        self, timeout_s: float, fds: Sequence[int], fds_key: object = None
    ) -> tuple[list[Reader[Any]], list[int]]:
        """Like :meth:`wait`, also woken by any of ``fds`` becoming readable.

        ``fds_key``: a value the caller changes whenever one of its descriptors may have
        been closed (its number then free for another file, which the WaitSet would not
        watch: a closed file leaves the kernel's epoll set by itself). While it and ``fds``
        stay the same the descriptors stay attached from one wait to the next: attaching
        and detaching one cost iceoryx2 seven system calls (it reads the kernel's watch
        limit from /proc each time), 13 a wake-up for the link's two sockets. None: they
        are attached for this one wait only. Returns the readers with data and the
        descriptors that are readable.
        """
        self._attach_fds(fds, fds_key)
        try:
            fired = self._wait(timeout_s)
            ready_fds = [self._fd_ids[a] for a in fired if a in self._fd_ids]
        finally:
            if fds_key is None:
                self._detach_fds()
        return self._settle(fired), ready_fds

    def _attach_fds(self, fds: Sequence[int], fds_key: object) -> None:
        kept = (*fds, fds_key)
        if fds_key is not None and kept == self._fds_kept:
            return
        self._detach_fds()  # first: a number reused would otherwise lose its new watch
        waitset = self._waitset
        self._fd_guards = [
            waitset.attach_notification_fd(iox2.FileDescriptor.non_owning_new(f)) for f in fds
        ]
        self._fd_ids = {
            iox2.WaitSetAttachmentId.from_guard(g): f
            for g, f in zip(self._fd_guards, fds, strict=True)
        }
        self._fds_kept = kept if fds_key is not None else None

    def _detach_fds(self) -> None:
        for guard in self._fd_guards:
            guard.delete()
        self._fd_guards, self._fd_ids, self._fds_kept = [], {}, None

    def _wait(self, timeout_s: float) -> list[Any]:
        """The WaitSet's fired attachments; it only looks when a sample already waits."""
        if any(r.has_samples() for r in self.triggers):
            return self._wait_once(_NO_WAIT)
        with self._idle:
            return self._wait_once(duration(timeout_s))

    def _wait_once(self, timeout: iox2.Duration) -> list[Any]:
        try:
            fired, _ = self._waitset.wait_and_process_with_timeout(timeout)
        except iox2.WaitSetRunError:
            return []  # interrupted by a signal: the caller checks its stop flag
        return list(fired)

    def _settle(self, fired: list[Any]) -> list[Reader[Any]]:
        """The readers with data, the triggers' notifications cleared (``_clear``)."""
        self._clear(fired)
        return [r for r in self.readers if r.has_samples()]

    def _clear(self, fired: list[Any]) -> None:
        """The notifications of the triggers that were woken or have data are cleared (the
        caller reads the data now, so one left would only end the next wait at once); the
        others' are left alone, each clearing being a system call, and a listener outside
        the WaitSet ends no wait (a writer's notification never fails for want of a
        listener clearing them)."""
        woken = {self._owners.get(a) for a in fired}
        for trigger in self.triggers:
            if trigger in woken or trigger.has_samples():
                trigger.consume_events()

    def close(self) -> None:
        """Detach from the readers and the descriptors."""
        self._detach_fds()
        for guard in self._guards:
            guard.delete()
        self._guards.clear()
        self._owners.clear()


_NO_WAIT = duration(0.0)


class GatedWaiter:
    """Two waits over the same readers, one of them also ended by the gated reader.

    For a process that needs a channel's samples only from some moment on: the link sends
    ATTITUDE on the first navigation state after it falls due (ten times a second), and
    woken by every state (fifty a second) it did its whole step four times in five for
    nothing. While the gate is shut the gated reader's samples wait unread, their
    wake-ups are cleared when it opens, and a sample still there ends the wait at once.
    """

    def __init__(
        self, gated: Reader[Any], others: Sequence[Reader[Any]], idle: IdleTally | None = None
    ) -> None:
        self.gated = gated
        self._open = Waiter((gated, *others), idle)
        self._shut = Waiter(others, idle)
        self._was_open = True

    def wait_with_fds(
        self, timeout_s: float, fds: Sequence[int], gate_open: bool, fds_key: object = None
    ) -> tuple[list[Reader[Any]], list[int]]:
        """:meth:`Waiter.wait_with_fds`; the gated reader ends it only when ``gate_open``
        (and is among the readers returned only then)."""
        if not gate_open:
            self._was_open = False
            return self._shut.wait_with_fds(timeout_s, fds, fds_key)
        if not self._was_open:
            self.gated.consume_events()
            self._was_open = True
        return self._open.wait_with_fds(timeout_s, fds, fds_key)

    def close(self) -> None:
        """Detach from the readers."""
        self._open.close()
        self._shut.close()
