"""Pseudo-terminals that stand in for serial devices in tests."""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from pathlib import Path


class Pty:
    """A pty whose slave is reached through a stable symlink, like /dev/ttyUSB0."""

    def __init__(self, link) -> None:
        self.link = link
        self.master, self.slave = os.openpty()
        if link.is_symlink():
            link.unlink()
        link.symlink_to(os.ttyname(self.slave))

    def write(self, text: str) -> None:
        os.write(self.master, text.encode())

    def vanish(self) -> None:
        os.close(self.master)
        os.close(self.slave)
        self.link.unlink()


class StreamingPty:
    """A pty whose other end a thread writes to at the device's rate, until stopped."""

    def __init__(
        self, link: Path, chunks: Callable[[int], bytes] | None = None, period_s: float = 0.05
    ) -> None:
        self.master, self.slave = os.openpty()
        os.set_blocking(self.master, False)  # an unread pty must not hold the writer
        link.symlink_to(os.ttyname(self.slave))
        self.link, self.chunks, self.period_s = link, chunks, period_s
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._write, daemon=True)

    def start(self) -> StreamingPty:
        self.thread.start()
        return self

    def _write(self) -> None:
        """``chunks(n)`` every period; None (which a test may set at any time): silence."""
        n = 0
        while not self.stop.wait(self.period_s):
            chunks = self.chunks
            if chunks is None:
                continue
            try:
                os.write(self.master, chunks(n))
            except (BlockingIOError, OSError):
                pass  # not opened yet: a device sends whether anyone listens or not
            n += 1

    def read_all(self) -> bytes:
        data = b""
        while True:
            try:
                chunk = os.read(self.master, 4096)
            except BlockingIOError:
                return data
            data += chunk

    def close(self) -> None:
        self.stop.set()
        self.thread.join(2)
        os.close(self.master)
        os.close(self.slave)
