"""Pseudo-terminals standing in for the aircraft's serial ports.

The bridge keeps both ends: it writes (or reads) the master, and holding the slave open
keeps the line up while a driver closes and reopens it, and lets the bridge ask how many
bytes the driver has not read yet (lockstep waits for that to reach zero).
"""

from __future__ import annotations

import errno
import fcntl
import logging
import os
import struct
import termios
import tty

log = logging.getLogger(__name__)


class PtyPort:
    """One emulated serial line; ``path`` is what the vehicle config names.

    With ``link``, the line is also reachable at that path (a symbolic link made here and
    removed on close), so a vehicle started separately can name it in its config.
    """

    def __init__(self, name: str, link: str | None = None) -> None:
        self.name = name
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)  # no echo, no line discipline: bytes pass as they are
        tty.setraw(self.master)
        os.set_blocking(self.master, False)
        self.path = os.ttyname(self.slave)
        self.link = link
        if link is not None:
            _replace_link(self.path, link)
            self.path = link
        self.bytes_out = 0
        self.dropped = 0  # bytes the driver left unread until the line's buffer was full

    def write(self, data: bytes) -> None:
        """Send bytes towards the driver; what does not fit is dropped and counted."""
        try:
            sent = os.write(self.master, data)
        except BlockingIOError:
            sent = 0
        except OSError as exc:
            if exc.errno != errno.EIO:
                raise
            sent = 0
        self.bytes_out += sent
        self.dropped += len(data) - sent

    def unread(self) -> int:
        """Bytes the driver has not read yet."""
        raw = fcntl.ioctl(self.slave, termios.FIONREAD, b"\0\0\0\0")
        return struct.unpack("i", raw)[0]

    def read(self) -> bytes:
        """What the vehicle wrote towards the device, without waiting."""
        chunks = []
        while True:
            try:
                chunk = os.read(self.master, 4096)
            except (BlockingIOError, OSError):
                break
            if not chunk:
                break
            chunks.append(chunk)
        return b"".join(chunks)

    def close(self) -> None:
        """Hang the line up."""
        if self.link is not None and os.path.islink(self.link):
            os.unlink(self.link)
        for fd in (self.master, self.slave):
            try:
                os.close(fd)
            except OSError:
                pass


def _replace_link(target: str, link: str) -> None:
    """Point ``link`` at ``target``; an old link (a bridge killed before its close) goes."""
    os.makedirs(os.path.dirname(os.path.abspath(link)), exist_ok=True)
    if os.path.islink(link):
        os.unlink(link)
    elif os.path.exists(link):
        raise ValueError(f"{link} exists and is not a link: not replaced")
    os.symlink(target, link)
