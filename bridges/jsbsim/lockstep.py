"""Pacing: lockstep (wait until the drivers have read every byte and the control loop has
answered) or a real-time factor."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, Protocol

from companion.time_grid import early_us

if TYPE_CHECKING:
    from companion.bus.node import Waiter
    from companion.bus.patterns import LatestReader, Reader

log = logging.getLogger(__name__)

# A driver that reads nothing for this long is not waited for: long enough that a busy
# machine starving a healthy driver does not count (CI saw 2 s pass), short beside a restart.
STALL_S = 5.0
EXACT_STALL_S = 10.0  # the same, when every frame must be the same run after run
EVENT_WAIT_S = 0.05  # exact: longest sleep on a bus event before looking again
# Exact: a driver's sample is waited for this long after its bytes (a loaded machine can
# starve a healthy driver for seconds, most of all one of ten plug-ins sharing a process)
SAMPLE_GRACE_S = EXACT_STALL_S
FIRST_SAMPLE_GRACE_S = 0.3  # ... and this long on a further channel that has carried nothing
# Exact: a sample published without waking its readers (the IMU's between two navigation
# states, ``sensors.serial_imu``'s ``wake_hz``) wakes nobody, the simulator included, which
# then looks for it this often instead of at the end of EVENT_WAIT_S: waited for that long,
# every such sample held an exact lockstep flight to real time.
SAMPLE_LOOK_S = 0.0005
SPIN_POLLS = 50  # polls that only yield the CPU before sleeping between polls
POLL_SLEEP_S = 50e-6
START_FLIGHT_S = 20.0  # the flight plug-ins' start-up after START, at most
STALL_FLIGHT_S = 5.0  # a running flight plug-in that stops answering is waited for this long


class SensorLine(Protocol):
    """What is waited on of a line: a pty, or a real serial line in hardware in the loop."""

    @property
    def name(self) -> str: ...
    def unread(self) -> int: ...


class Lockstep:
    """Waits, each frame, until every sensor line is drained by its driver.

    A driver that stops reading (it crashed, or is restarting) stalls one frame for at most
    ``stall_s`` (a loaded machine can starve a healthy driver for a while, so exact runs
    wait much longer); its line is then left out until the driver drains it again, so one dead
    driver slows the simulation down once instead of on every frame.
    """

    def __init__(self, ports: Sequence[SensorLine], stall_s: float = STALL_S) -> None:
        self.ports = ports
        self.stall_s = stall_s
        self.waiting_for = {p.name: True for p in ports}
        self.stalls = 0
        self.wait_s = 0.0

    def wait(self) -> None:
        """Return when the drivers have read what they were sent (or one stalled)."""
        started = time.perf_counter()
        polls = 0
        for port in self.ports:
            if not self.waiting_for[port.name]:
                self.waiting_for[port.name] = port.unread() == 0
        pending = [p for p in self.ports if self.waiting_for[p.name]]
        while pending:
            pending = [p for p in pending if p.unread() > 0]
            if not pending:
                break
            if time.perf_counter() - started > self.stall_s:
                for port in pending:
                    log.warning("lockstep: %s driver is not reading; not waiting for it", port.name)
                    self.waiting_for[port.name] = False
                self.stalls += 1
                break
            polls += 1
            time.sleep(0 if polls < SPIN_POLLS else POLL_SLEEP_S)
        self.wait_s += time.perf_counter() - started


class RealTime:
    """Keeps simulation time at ``speed`` times wall time."""

    def __init__(self, speed: float) -> None:
        self.speed = speed
        self.start_wall: float | None = None
        self.late_s = 0.0  # the most the simulation has fallen behind

    def restart(self) -> None:
        """Pace on from the next frame, as if the simulation had started there."""
        self.start_wall = None

    def wait(self, t_s: float) -> None:
        """Sleep until wall time catches up with simulation time ``t_s``."""
        now = time.monotonic()
        if self.start_wall is None:
            self.start_wall = now - t_s / self.speed
        delay = self.start_wall + t_s / self.speed - now
        if delay > 0:
            time.sleep(delay)
        else:
            self.late_s = max(self.late_s, -delay)


class _BusWait:
    """Sleeps on bus events until a condition holds, the simulation ends, or time is up."""

    def __init__(self, waiter: Waiter) -> None:
        self.waiter = waiter
        self.look_s = EVENT_WAIT_S  # the longest sleep before looking again
        self.wait_s = 0.0
        self.cancelled = False  # the simulation is ending: wait for nothing more
        # Called every ``EVENT_WAIT_S`` while the simulation is held: the bridge hands its
        # clock to readers that joined meanwhile (a plug-in restarted during the hold read
        # simulation time 0 until the next frame, which waited for that very plug-in).
        self.on_hold: Callable[[], None] | None = None

    def _until(self, done: Callable[[], bool], limit_s: float) -> bool:
        """True once ``done()`` (or cancelled); False when ``limit_s`` passed first."""
        started = time.perf_counter()
        try:
            while not done():
                if self.cancelled:
                    return True
                waited = time.perf_counter() - started
                if waited > limit_s:
                    return False
                self.waiter.wait(min(limit_s - waited, self.look_s))
                if self.on_hold is not None and waited >= EVENT_WAIT_S:
                    self.on_hold()
            return True
        finally:
            self.wait_s += time.perf_counter() - started


class FlightSync(_BusWait):
    """Lockstep with a vehicle process that answers a fixed grid of vehicle time.

    The vehicle's navigator publishes on a fixed grid of vehicle time (``period_us``), the
    controller answers each state, and the servo plug-in says which command its bytes
    answer (``ServoOutput.command_t_us``). At each grid instant the bridge waits for that
    answer before it reads the servo line, so every command is applied at the same frame
    whatever the scheduler did. Only while the flight plug-ins run (from the START ack to
    STOP); a flight plug-in that does not answer is waited for ``stall_s`` once, then not
    until it catches up again.

    ``lag_periods`` > 0 (fast lockstep) lets the answer trail by that many grid periods,
    so the vehicle's processes run beside the physics instead of after it, while a late
    process still holds the simulation: sim time never runs ahead of what the vehicle has
    consumed (its queues would overflow and it would navigate and fly on a gap).
    ``stamp`` names the answer's time field; ``always`` waits whether or not the flight
    plug-ins run (for the navigator), from its first answer on, or with ``from_start``
    for that first answer too.
    """

    def __init__(
        self,
        period_us: int,
        answers: LatestReader[Any],
        waiter: Waiter,
        lag_periods: int = 0,
        stamp: str = "command_t_us",
        always: bool = False,
        from_start: bool = False,
    ) -> None:
        super().__init__(waiter)
        self.period_us = period_us
        self.early_us = early_us(period_us)
        self.answers = answers
        self.lag_us = lag_periods * period_us
        self.stamp, self.always = stamp, always
        self.from_start = from_start  # ``always``, and its first answer is waited for too
        self.flying = False  # the flight plug-ins were started
        self.synced = False  # they have answered in step since
        self.lagging = False  # they stopped answering: not waited for until they catch up
        self.answered_us = -1
        self.stalls = 0

    def started(self, flying: bool) -> None:
        """START acknowledged (True) or STOP seen (False)."""
        self.flying, self.synced, self.lagging = flying, False, False

    def wait(self, t_us: int) -> None:
        """Return once the answer to the newest grid state at or before ``t_us`` is in."""
        if self.always:
            self._answered(0)
            if self.answered_us < 0 and not self.from_start:
                return  # not started yet: nothing to keep in step with
        elif not self.flying:
            return
        grid = (t_us - self.lag_us) // self.period_us * self.period_us
        # A navigator with its samples near the ticks answers a tick with the sample just
        # before it (companion.time_grid); a simulation's samples are never there.
        due = grid - self.early_us + 1 if grid > 0 else grid
        if self._answered(due) or self.lagging:
            return
        started = self.synced or (self.always and self.answered_us >= 0)
        limit = STALL_FLIGHT_S if started else START_FLIGHT_S
        if not self._until(lambda: self._answered(due), limit):
            log.warning(
                "lockstep: no answer to the state at %.2f s for %.0f s (newest"
                " answer: %.2f s); not waiting for it",
                grid / 1e6,
                limit,
                self.answered_us / 1e6,
            )
            self.lagging, self.synced = True, False
            self.stalls += 1

    def _answered(self, grid: int) -> bool:
        answer = self.answers.get()
        if answer is not None and getattr(answer, self.stamp) > self.answered_us:
            self.answered_us = int(getattr(answer, self.stamp))
        if self.answered_us < grid:
            return False
        self.synced, self.lagging = True, False
        return True


class SampleSync(_BusWait):
    """Exact lockstep with the drivers: wait until each device's bytes became samples.

    A drained pty only says the driver read the bytes; the kernel may also still hold
    them in the pty's buffer while reporting nothing unread, and the driver may not have
    published yet. Waiting for every sample a write produces on the bus (each channel the
    device's driver publishes, stamped with this frame's time) closes these gaps, so no
    driver reads two frames as one or publishes one late.

    Every write of a device gives a sample on its first channel (``DEVICE_CHANNELS``), so
    that one is waited for from the first write on, as long as a driver has a writer on it
    (``grace_s``, counted in ``late`` when it passes: the frame is then no longer the same
    run after run). A further channel of the device that has never carried anything is
    waited for only ``first_grace_s`` after the first channel's sample came, the driver
    publishing both from the same reading. (No emulated device has one today: the IMU's
    driver publishes its magnetometer and pressure before the IMU sample, and not with
    every one, so they are not waited for.)
    """

    def __init__(
        self,
        channels: dict[str, dict[str, Reader[Any]]],
        waiter: Waiter,
        grace_s: float = SAMPLE_GRACE_S,
        first_grace_s: float = FIRST_SAMPLE_GRACE_S,
    ) -> None:
        super().__init__(waiter)
        self.look_s = SAMPLE_LOOK_S
        self.channels = channels  # device → {channel: reader}, its first channel first
        self.newest_us = {c: -1 for readers in channels.values() for c in readers}
        self.grace_s, self.first_grace_s = grace_s, first_grace_s
        self.late = 0  # frames in which a sample did not come within grace_s

    def wait(self, written: set[str], t_us: int) -> None:
        """Return when every device written this frame has published its samples."""
        firm: list[str] = []  # waited for up to grace_s
        loose: list[str] = []  # never heard: waited for briefly once the firm ones came
        for device in sorted(written):
            for i, (name, reader) in enumerate(self.channels.get(device, {}).items()):
                heard = self.newest_us[name] >= 0
                (firm if heard or (i == 0 and reader.writers() > 0) else loose).append(name)
        if not self._until(lambda: self._arrived(firm, t_us), self.grace_s):
            self.late += 1
        if loose:
            self._until(lambda: self._arrived(loose, t_us), self.first_grace_s)

    def _arrived(self, names: list[str], t_us: int) -> bool:
        self._take()
        return all(self.newest_us[c] >= t_us for c in names)

    def _take(self) -> None:
        for readers in self.channels.values():
            for channel, reader in readers.items():
                for sample in reader.drain():
                    self.newest_us[channel] = max(self.newest_us[channel], int(sample.t_us))
