"""The scheduling priority of a plug-in: the Linux nice value its config or class asks for.

When a board's CPU is short (a small core, a CPU quota, other work), Linux shares it by
weight: each nice step is about 25 % of weight. The flight chain asks for
``companion.plugin.FLIGHT_NICE`` so that the link, the flight log and the slower sensors
give way to it first, as a flight stack's scheduler runs its rate loop before telemetry.
Nice is a thread's on Linux, so plug-ins composed into one process keep their own.

On the hardware time base (a real aircraft, hardware in the loop) the flight chain also
runs under ``SCHED_FIFO`` at the vehicle's ``realtime_priority``, as a flight stack's rate
loop runs on Linux: woken, it runs before any normal process, however busy the board, so
its latency does not depend on the other work there. A simulation's clock leaves it at its
nice value: exact lockstep keeps a thread busy for as long as the simulator feeds it.
"""

from __future__ import annotations

import logging
import os
import resource
from collections.abc import Iterable, Mapping
from typing import Any, Protocol

NICE_MIN, NICE_MAX = -20, 19
_CAP_SYS_NICE = 23  # the capability's bit in /proc/PID/status CapEff

log = logging.getLogger("companion.priority")


class HasNice(Protocol):
    @property
    def name(self) -> str: ...
    @property
    def nice(self) -> int: ...


def can_raise(by: int) -> bool:
    """Whether this process may lower its nice value by ``by`` steps: root, CAP_SYS_NICE,
    or an RLIMIT_NICE that reaches that far."""
    if os.geteuid() == 0:
        return True
    try:
        with open("/proc/self/status") as status:
            caps = next(ln.split()[1] for ln in status if ln.startswith("CapEff:"))
        if int(caps, 16) >> _CAP_SYS_NICE & 1:
            return True
    except (OSError, StopIteration, ValueError):
        pass
    soft, _hard = resource.getrlimit(resource.RLIMIT_NICE)
    lowest = 20 - soft if soft != resource.RLIM_INFINITY else NICE_MIN
    return lowest <= os.nice(0) - by


def note_refused_raises(specs: Iterable[HasNice]) -> None:
    """Say once, for the whole vehicle, when the flight chain cannot be put first."""
    raised = [s for s in specs if s.nice < 0]
    if raised and not can_raise(max(-s.nice for s in raised)):
        log.info(
            "%s run at the same priority as the rest: raising it needs CAP_SYS_NICE"
            " (root, or the service unit's AmbientCapabilities)",
            ", ".join(s.name for s in raised),
        )


def apply_nice(name: str, nice: int) -> int:
    """Move the calling thread ``nice`` steps from the supervisor's priority (threads it
    starts afterwards inherit it); the nice value it runs at. A raise the system refuses
    leaves it where it is (the supervisor has said so: ``note_refused_raises``)."""
    if nice == 0:
        return os.nice(0)
    try:
        return os.nice(nice)
    except PermissionError:
        log.debug("%s: nice %+d refused", name, nice)
        return os.nice(0)


def realtime_priority(nice: int, vehicle: Mapping[str, Any]) -> int:
    """The ``SCHED_FIFO`` priority a plug-in asks for: the vehicle's ``realtime_priority``
    for the flight chain (a negative nice) on the hardware time base, 0 (none) otherwise."""
    if nice >= 0 or vehicle.get("clock", "monotonic") != "monotonic":
        return 0
    return int(vehicle.get("realtime_priority", 0))


def apply_priority(name: str, nice: int, vehicle: Mapping[str, Any]) -> str:
    """The calling thread's scheduling: its nice value, then ``SCHED_FIFO`` when it asks
    for it (``realtime_priority``) and the system allows it. Says which ("nice -5",
    "fifo 10"). A refusal leaves the nice value; it is said here only when the raise of the
    nice value went through (a cgroup given no real-time time): without CAP_SYS_NICE the
    supervisor has said so once for the whole vehicle (``note_refused_raises``). Processes
    it starts get normal scheduling (``SCHED_RESET_ON_FORK``); threads inherit it."""
    at = apply_nice(name, nice)
    rt = realtime_priority(nice, vehicle)
    if rt <= 0:
        return f"nice {at}"
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO | os.SCHED_RESET_ON_FORK, os.sched_param(rt))
    except OSError as exc:  # EPERM: no capability, or a cgroup with no real-time runtime
        said = log.info if at == nice else log.debug
        said("%s: SCHED_FIFO %d refused (%s); it runs at nice %d", name, rt, exc, at)
        return f"nice {at}"
    return f"fifo {rt}"
