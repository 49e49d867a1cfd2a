"""The thesis's two shared-memory patterns on iceoryx2: Queue and Latest.

Both are a publish-subscribe service plus an event service of the same name: a writer
sends the sample and then notifies, a reader sleeps on the event with a timeout. Each
sample carries a small header (writer id, sequence number) so a reader can count what a
full buffer made it lose.

- Queue: every sample in order to every reader; a reader that falls behind loses the
  oldest samples (iceoryx2 "safe overflow"), the writer never blocks, the loss is counted.
- Latest: a buffer of one with history one, so a reader always sees the newest value,
  including one published before it connected (once the writer's process has called
  ``BusNode.update_connections``, which the plug-in host and the supervisor do often). A
  reader that wants every value (the flight log) may keep up to the channel's depth.
"""

from __future__ import annotations

import ctypes
import logging
import random
import time
from collections import deque
from collections.abc import Callable, Iterator
from typing import Any, Generic, TypeVar

import iceoryx2 as iox2

from companion.bus.chunks import ReaderChunks, SampleHeader, WriterChunks
from companion.messages import Message

__all__ = ["IdleTally", "LatestReader", "QueueReader", "Reader", "SampleHeader", "Writer"]

log = logging.getLogger(__name__)

M = TypeVar("M", bound=Message)

_MAX_WAIT_S = 3600.0
_MIN_LISTENER_WAIT_S = 1e-6
_MAX_AHEAD = 64  # LatestReader.before(): values kept that are not older yet


# iceoryx2's Python wrappers around loaning and initialising a sample check the payload's
# type on every sample; the channel's type is fixed when its service is opened, so a writer
# calls what they call, once it has checked the message's size itself. Header and payload
# are read and written in place (``chunks``): a copy into or out of shared memory stays in
# C, where ``ctypes.memmove`` goes through libffi's argument conversion, several times the
# cost, on every sample of every reader.
_loan_uninit = getattr(iox2.Publisher, "__loan_uninit")
_assume_init = getattr(iox2.SampleMutUninit, "__assume_init")


def duration(timeout_s: float) -> iox2.Duration:
    """An iceoryx2 Duration from seconds (clamped to [0, 1 h])."""
    return iox2.Duration.from_secs_f64(min(max(timeout_s, 0.0), _MAX_WAIT_S))


def listener_timeout(timeout_s: float) -> iox2.Duration:
    """A Listener's timeout: a zero Duration makes its ``timed_wait`` wait for ever (a
    WaitSet's does not wait at all), so the shortest one is a microsecond."""
    return duration(max(timeout_s, _MIN_LISTENER_WAIT_S))


class IdleTally:
    """Time a process spent asleep in bus waits, so step time can exclude it."""

    def __init__(self) -> None:
        self.seconds = 0.0
        self._since = 0.0

    def __enter__(self) -> IdleTally:
        self._since = time.perf_counter()
        return self

    def __exit__(self, *exc: object) -> None:
        self.add_since(self._since)

    def add_since(self, started: float) -> None:
        """Count the time since ``started`` (``time.perf_counter()``) as idle: a hot wait's
        one call instead of the context manager's two."""
        self.seconds += time.perf_counter() - started


class Writer(Generic[M]):
    """Publishes samples of one channel and wakes its readers."""

    def __init__(
        self,
        name: str,
        publisher: iox2.Publisher,
        notifier: iox2.Notifier,
        msg_type: type[Message],
        service: Any = None,
    ) -> None:
        self.name = name
        self._type = msg_type
        self._size = ctypes.sizeof(msg_type)
        self._chunks = WriterChunks(msg_type)
        self._kept = self._chunks.kept
        self._service = service
        self._publisher = publisher
        self._notifier = notifier
        self._writer_id = random.getrandbits(63)
        self._seq = 0
        self.sent = 0

    def publish(self, msg: M, wake: bool = True) -> None:
        """Copy the message into shared memory, send it, and notify readers (unless not
        ``wake``: a value whose news a reader only looks at when it reads, such as a table's
        counters, need not end anybody's sleep)."""
        # The channel's own type needs no size check (the usual case: a call less).
        if type(msg) is not self._type and ctypes.sizeof(msg) != self._size:
            raise TypeError(f"{self.name}: a {type(msg).__name__} is not this channel's type")
        sample = _loan_uninit(self._publisher)
        header, box = self._kept.get(sample.payload_ptr) or self._chunks.add(sample)
        header.writer_id = self._writer_id
        header.seq = self._seq
        self._seq += 1
        try:
            box.msg = msg
        except TypeError:  # a message of another type, of the same size: its bytes
            memoryview(box).cast("B")[:] = memoryview(msg).cast("B")
        _assume_init(sample).send()
        if wake:
            self._notifier.notify()
        self.sent += 1

    def readers(self) -> int:
        """How many readers the channel has now (0 when unknown)."""
        if self._service is None:
            return 0
        return int(self._service.dynamic_config.number_of_subscribers)

    def update_connections(self) -> None:
        """Hand the history (the last sample) to readers that joined since the last send.

        iceoryx2 delivers history only when the publisher next sends or is asked to update
        its connections, so a Latest writer that publishes rarely must be asked.
        """
        self._publisher.update_connections()

    def close(self) -> None:
        """Release the iceoryx2 ports and the service (which holds the node alive)."""
        self._notifier.delete()
        self._publisher.delete()
        self._service = None


class Reader(Generic[M]):
    """Receives samples of one channel; waits on its event without polling."""

    def __init__(
        self,
        name: str,
        msg_type: type[M],
        subscriber: iox2.Subscriber,
        listener: iox2.Listener,
        idle: IdleTally | None = None,
        service: iox2.PortFactoryPublishSubscribe | None = None,
    ) -> None:
        self.name = name
        self._idle = idle or IdleTally()
        self._service = service
        self.msg_type = msg_type
        self._copy = msg_type.from_buffer_copy
        self._chunks = ReaderChunks(msg_type, headers=self.counts_losses)
        self._kept = self._chunks.kept
        self._subscriber = subscriber
        # True when a sample is waiting: iceoryx2's own call (it gives a bool), not one of
        # ours around it, asked by every wait and chained step.
        self.has_samples: Callable[[], bool] = subscriber.has_samples
        self.listener = listener
        # Losses are counted from the first sample seen of each writer onwards.
        self._last_seq: dict[int, int] = {}
        self.received = 0
        self.lost = 0
        # Its notifications were taken just now (``take_notifications``): the next
        # ``consume_events`` has none to clear and makes no system call.
        self._taken = False

    # Whether a skipped sequence number is a loss (a Latest reader skips by design, and
    # then does not read the sample's header at all: a ctypes object on every value).
    counts_losses = True

    def _take(self, sample: Any) -> M:
        """A received sample's message (copied out), its losses counted; the sample freed."""
        header, payload = self._kept.get(sample.payload_ptr) or self._chunks.add(sample)
        if header is not None:  # a skipped sequence number is a loss
            writer_id, seq = header.writer_id, header.seq
            last = self._last_seq.get(writer_id)
            if last is not None and seq > last + 1:
                self.lost += seq - last - 1
            self._last_seq[writer_id] = seq
        msg = self._copy(payload)
        sample.delete()
        self.received += 1
        return msg

    def drain(self) -> Iterator[M]:
        """Every sample available now, oldest first, without waiting."""
        subscriber = self._subscriber
        while (sample := subscriber.receive()) is not None:
            yield self._take(sample)

    def pending(self) -> list[M]:
        """What ``drain`` gives, as a list: without a generator (the navigator asks its five
        readers at every IMU sample, most of them holding none: an empty reader costs the
        one ``receive`` and no call of our own)."""
        subscriber = self._subscriber
        out: list[M] = []
        while (sample := subscriber.receive()) is not None:
            out.append(self._take(sample))
        return out

    def wait_event(self, timeout_s: float) -> bool:
        """Sleep until a writer notifies or the timeout passes; True when woken by data.

        A signal (SIGINT/SIGTERM) ends the wait early and returns False, so a plug-in's
        step() returns promptly and its runner can stop.
        """
        if self._subscriber.has_samples():
            self.consume_events()
            return True
        self._taken = False
        try:
            with self._idle:
                events = self.listener.timed_wait(listener_timeout(timeout_s))
        except iox2.ListenerWaitError:
            return False
        # timed_wait has consumed the notifications it returned.
        return bool(events) or self._subscriber.has_samples()

    def take_notifications(self) -> bool:
        """Whether a writer notified since the last wait (the notifications are taken): a
        sample published without waking (``Writer.publish``'s ``wake``) leaves none.

        The next ``consume_events`` then clears nothing: a composed plug-in's chain takes
        its trigger's notification before its step, whose wait cleared it again, two
        ``recvfrom`` finding none (iceoryx2's ``try_wait`` on an empty listener; one
        finding a notification is one). A notification that comes between the two stays,
        and ends a later wait early as any stale wake-up does."""
        self._taken = True
        try:
            return bool(self.listener.try_wait())
        except iox2.ListenerWaitError:
            return False

    def consume_events(self) -> None:
        """Clear pending notifications (they are only wake-ups; data is in the queue)."""
        if self._taken:
            self._taken = False
            return
        self.take_notifications()
        self._taken = False

    def writers(self) -> int:
        """How many writers the channel has now (0 when unknown)."""
        if self._service is None:
            return 0
        return int(self._service.dynamic_config.number_of_publishers)

    def close(self) -> None:
        """Release the iceoryx2 ports and the service (which holds the node alive)."""
        self.listener.delete()
        self._subscriber.delete()
        self._service = None


class QueueReader(Reader[M]):
    """Reader of a Queue channel: ordered samples, losses counted in ``lost``."""

    def take(self, timeout_s: float = 0.0) -> list[M]:
        """All pending samples, waiting up to ``timeout_s`` for the first one."""
        deadline = time.monotonic() + timeout_s
        msgs = self.pending()
        # A wake-up can be stale (its sample already taken): sleep again until the deadline.
        while not msgs and (left := deadline - time.monotonic()) > 0:
            self.wait_event(left)
            msgs = self.pending()
        return msgs


class LatestReader(Reader[M]):
    """Reader of a Latest channel: the newest value, cached between updates."""

    counts_losses = False  # skipping superseded values is what Latest is for

    def __init__(
        self,
        name: str,
        msg_type: type[M],
        subscriber: iox2.Subscriber,
        listener: iox2.Listener,
        idle: IdleTally | None = None,
        service: iox2.PortFactoryPublishSubscribe | None = None,
    ) -> None:
        super().__init__(name, msg_type, subscriber, listener, idle, service)
        self._latest: M | None = None
        self._waited = False
        self._ahead: deque[M] = deque(maxlen=_MAX_AHEAD)  # for before(): not yet older
        self._before: M | None = None

    def first(self, timeout_s: float) -> M | None:
        """The newest value; the first call waits up to ``timeout_s`` for one if a writer exists.

        A value published before this reader joined reaches it only once the writer's
        process sends again or updates its connections, an instant set by that process's
        scheduling: a reader that must start from the writer's state (the flight
        controller from the commander's mode) waits for it rather than acting without it.
        """
        value = self.get()
        if value is None and not self._waited and self.writers() > 0:
            value = self.wait(timeout_s)
        self._waited = True  # once: a writer that never speaks costs one wait, not one a call
        return value

    def before(self, t_us: int) -> M | None:
        """The newest value stamped before ``t_us`` of those received (None: none yet).

        For a reader that acts on another channel's sample of time ``t_us`` (the flight
        controller on a navigation solution): a value stamped with that very instant may or
        may not have come when it runs, as the processes happened to be scheduled, while in
        exact lockstep every earlier one has (the simulator waited for it). So what it reads
        depends on the data alone. Its reader keeps (``latest_reader(keep=...)``) the values
        that come between two calls; use either this or ``get()`` on one reader.
        """
        for msg in self.pending():
            self._latest = msg
            self._ahead.append(msg)
        while self._ahead and self._ahead[0].t_us < t_us:
            self._before = self._ahead.popleft()
        return self._before

    def get(self) -> M | None:
        """The newest value published so far, or None if nothing has been seen yet."""
        # ``pending`` and ``_take`` inlined: readers of the clock and of the link's snapshot call
        # this a dozen times a step, most often to find nothing new.
        # The subscriber, not its bound ``receive``: making that method object cost more
        # than the call itself when, as most often, there is nothing.
        subscriber = self._subscriber
        while (sample := subscriber.receive()) is not None:
            chunk = self._kept.get(sample.payload_ptr) or self._chunks.add(sample)
            self._latest = self._copy(chunk[1])
            sample.delete()
            self.received += 1
        return self._latest

    def wait(self, timeout_s: float) -> M | None:
        """Wait up to ``timeout_s`` for a NEW value; None if none arrived."""
        deadline = time.monotonic() + timeout_s
        fresh: M | None = None
        if msgs := self.pending():
            fresh = msgs[-1]
        while fresh is None and (left := deadline - time.monotonic()) > 0:
            self.wait_event(left)
            if msgs := self.pending():
                fresh = msgs[-1]
        if fresh is not None:
            self._latest = fresh
        return fresh
