"""One flight log at a time in a ``LogDirectory``: crash-safe to open, bounded in size.

A log appears under its final name only once its header is on disk (it is written under a
hidden partial name, fsynced, then renamed), so a power cut at the wrong moment never leaves
an empty or headless ``.ulg`` for a ground station to choke on. At every flush the directory
is pruned to its budget, and a file that reached ``max_bytes`` is closed and the log goes
on in a new one: a long flight, or a log from boot, never outgrows the budget.
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import BinaryIO

from companion.flight_log.files import LogDirectory, hold
from companion.flight_log.ulog import ULogWriter
from companion.messages.base import Message

log = logging.getLogger(__name__)

BUFFER_BYTES = 256 * 1024


class LogRecorder:
    """Opens, flushes, rotates and closes the logs of one writer (the logger plug-in).

    ``params`` is read at each opening (the caller keeps it current), so a file that
    continues a rotated log starts with the parameters as they are then.
    """

    def __init__(
        self,
        logs: LogDirectory,
        topics: Sequence[tuple[str, type[Message]]],
        info: Mapping[str, str | int | float],
        params: Mapping[str, int | float],
        max_bytes: int,
    ) -> None:
        self.logs = logs
        self.topics = topics
        self.info = info
        self.params = params
        self.max_bytes = max_bytes
        self.label = ""
        self.path: Path | None = None
        self.file: BinaryIO | None = None
        self.writer: ULogWriter | None = None
        for path in logs.remove_partial():
            log.info("removed %s (a log cut off before its header was on disk)", path.name)

    @property
    def is_open(self) -> bool:
        return self.writer is not None

    def open(self, label: str, now_us: int) -> Path:
        """Start a new log; its path (visible once its header is on disk)."""
        self.label = label
        self.path = self.logs.new_path(label)
        partial = self.logs.partial_path(self.path)
        self.file = open(partial, "wb", buffering=BUFFER_BYTES)  # noqa: SIM115 - kept open
        hold(self.file)  # LOG_ERASE leaves it alone while it is written
        self.writer = ULogWriter(self.file, now_us, self.topics, self.info, self.params)
        self._sync()
        self.logs.publish(partial, self.path)
        self._prune()
        log.info("logging to %s", self.path)
        return self.path

    def flush(self, now_us: int) -> None:
        """Everything written so far onto the disk; then keep within the budget and, past
        ``max_bytes``, go on in a new file (at a sync point, so nothing is split)."""
        self._sync()
        self._prune()
        if self.writer is not None and self.writer.bytes_written >= self.max_bytes:
            log.info("%s reached %d bytes; continuing in a new file", self.path, self.max_bytes)
            self.close()
            self.open(self.label, now_us)

    def close(self) -> None:
        """Flush and close the log (if one is open)."""
        if self.file is None:
            return
        self._sync()
        self.file.close()
        log.info("closed %s", self.path)
        self.file = self.writer = None
        self._prune()

    def abandon(self) -> None:
        """Let the file go without writing more (the card failed): what reached it stays."""
        if self.file is not None:
            with contextlib.suppress(OSError):
                self.file.close()
        self.file = self.writer = None

    def _sync(self) -> None:
        assert self.file is not None and self.writer is not None
        self.writer.sync()
        self.file.flush()
        os.fsync(self.file.fileno())

    def _prune(self) -> None:
        for path in self.logs.prune(keep=self.path):
            log.info("removed old log %s (over the disk budget)", path.name)
