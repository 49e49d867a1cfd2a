"""The scheduling priority of a plug-in: the Linux nice value its config or class asks for.

When a board's CPU is short (a small core, a CPU quota, other work), Linux shares it by
weight: each nice step is about 25 % of weight. The flight chain asks for
``companion.plugin.FLIGHT_NICE`` so that the link, the flight log and the slower sensors
give way to it first, as a flight stack's scheduler runs its rate loop before telemetry.
Nice is a thread's on Linux, so plug-ins composed into one process keep their own.
"""

from __future__ import annotations

import logging
import os

NICE_MIN, NICE_MAX = -20, 19

log = logging.getLogger("companion.priority")


def apply_nice(name: str, nice: int) -> int:
    """Move the calling thread ``nice`` steps from the supervisor's priority (threads it
    starts afterwards inherit it); the nice value it runs at. A raise the system refuses
    (it needs CAP_SYS_NICE: root, or the service unit's capability) leaves it where it is."""
    if nice == 0:
        return os.nice(0)
    try:
        return os.nice(nice)
    except PermissionError:
        log.info(
            "%s runs at the supervisor's priority: nice %+d needs CAP_SYS_NICE"
            " (root, or the service unit's AmbientCapabilities)",
            name,
            nice,
        )
        return os.nice(0)
