"""A tty's reader woken only once enough bytes have come (termios VMIN), not at the first.

A driver that has work only every few frames (the IMU's, whose navigator makes a state
every second sample) would wake for each frame on its port and do little with the ones
between: on a small board a wake-up of a Python process costs about what decoding the
frame does (``benchmarks/wake_floor.py``). In non-canonical mode with VTIME 0, Linux's poll
on a tty (a serial adapter's or a pty) says readable only once VMIN bytes are waiting, so
the kernel holds the frames until the one that matters has come, and the reader wakes once.

Two things of Linux's tty layer shape the reads: VMIN is one byte (255 at most), and from
Linux 5.11 a non-blocking read of a tty whose VMIN is over 64 hands over at most 64 bytes
(``tty_read``'s buffer), while poll then stays unreadable until VMIN more have come; so
such a read goes on until a piece comes back short.
"""

from __future__ import annotations

import logging
import os
import termios

log = logging.getLogger(__name__)

MAX_WAKE_BYTES = 255  # c_cc[VMIN] is an unsigned char
TTY_READ_PIECE = 64  # what one read of such a tty hands over at most (Linux 5.11 on)


class WakeBytes:
    """The VMIN of one open tty: set when it changes, left at 1 when the tty refuses it."""

    def __init__(self, fd: int) -> None:
        self.fd = fd
        self.count = 1  # as pyserial leaves an open port
        self._attrs: list | None = None  # tcgetattr's, kept: asked once, not at every change
        self.refused = False  # not a tty (a FIFO, a file): woken at the first byte, always

    def set(self, n_bytes: int) -> None:
        """Wake the tty's reader once ``n_bytes`` are waiting (1 to 255; clamped)."""
        n = min(max(1, n_bytes), MAX_WAKE_BYTES)
        if n == self.count or self.refused:
            return
        try:
            if self._attrs is None:
                self._attrs = termios.tcgetattr(self.fd)
            cc = self._attrs[6]
            cc[termios.VMIN], cc[termios.VTIME] = n, 0
            termios.tcsetattr(self.fd, termios.TCSANOW, self._attrs)
        except termios.error as exc:
            log.info("fd %d takes no VMIN (%s): woken at every byte", self.fd, exc)
            self.refused = True
            return
        self.count = n

    def read_rest(self, first: bytes, size: int) -> bytes:
        """``first`` (the read after the wake-up) and what else is waiting, up to ``size``:
        with VMIN over 64 the kernel hands the bytes over 64 at a time."""
        if self.count <= TTY_READ_PIECE or len(first) != TTY_READ_PIECE:
            return first
        data = bytearray(first)
        while len(data) < size:
            try:
                piece = os.read(self.fd, size - len(data))
            except (BlockingIOError, InterruptedError):
                break
            data += piece
            if len(piece) < TTY_READ_PIECE:
                break
        return bytes(data)
