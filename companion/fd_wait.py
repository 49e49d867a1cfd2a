"""Sleep until one of a few file descriptors is readable, whatever their numbers.

``select.select`` refuses descriptors numbered 1024 or more, and a process that hosts
many plug-ins (each with its bus ports, devices and pipes) reaches that; ``poll`` does not.
"""

from __future__ import annotations

import math
import os
import select
from collections.abc import Sequence


def wait_readable(fds: Sequence[int], timeout_s: float | None) -> list[int]:
    """The descriptors of ``fds`` readable within ``timeout_s`` (None: no limit)."""
    poller = select.poll()
    for fd in fds:
        poller.register(fd, select.POLLIN)
    timeout_ms = None if timeout_s is None else max(0, math.ceil(timeout_s * 1000))
    return [fd for fd, _ in poller.poll(timeout_ms)]


def drain(fd: int) -> None:
    """Empty a non-blocking wake-up pipe, so it wakes the next wait only for a new byte."""
    try:
        while os.read(fd, 256):
            pass
    except OSError:  # empty (BlockingIOError), interrupted, or closed: nothing to take
        pass
