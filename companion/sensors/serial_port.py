"""A serial device that comes back: read and write never raise, a vanished device is reopened.

Device URLs:
- ``serial://PATH[:BAUD]``: our form, the one MAVLink endpoints use too
  (``serial:///dev/ttyUSB0:57600``). The baud rate is the last ``:digits`` suffix; without
  it the ``baud`` argument is used. Give it explicitly when PATH itself ends in ``:digits``.
- a plain path: a device (``/dev/ttyUSB0``), a symlink to one, or a pseudo-terminal.
- any pyserial URL: ``socket://host:port``, ``loop://``, ``rfc2217://…``.

Reads block at most ``read_timeout_s`` (a poll on a device's descriptor, pyserial's own
timeout on the other URLs). When the device goes (unplugged USB adapter, a pty whose master
closed, a socket whose peer left), the port is closed, ``reopens`` counts it, and opening is
retried with back-off (0.1 s doubling to 2 s). While waiting, ``read`` sleeps at most
``read_timeout_s`` per call, so the caller's ``step()`` still returns regularly.

A ``stop_fd`` (the plug-in host's signal wake-up pipe) ends a wait on a device at once: a
stop request then needs no short timeout to be seen, so a silent device costs one wake-up
per read timeout (a second), not several.
"""

from __future__ import annotations

import fcntl
import logging
import os
import select
import sys
import termios
import threading
import time
from collections.abc import Callable, Mapping
from typing import Any, Protocol

import serial

from companion.fd_wait import drain
from companion.sensors.termios2_serial import port_class
from companion.sensors.tty_wake import WakeBytes

log = logging.getLogger(__name__)
FIRST_RETRY_S = 0.1
MAX_RETRY_S = 2.0
SCHEME = "serial://"
# What pyserial raises when a device is gone or cannot be opened (SerialException is an
# OSError; ValueError for a malformed URL; TypeError when a port closes under a read).
_PORT_ERRORS = (serial.SerialException, OSError, ValueError, TypeError)
# The ioctl pyserial's out_waiting makes, asked of a descriptor directly: the servo output
# asks it on every command.
_TIOCOUTQ = getattr(termios, "TIOCOUTQ", 0x5411)
_UINT_ZERO = bytes(4)


class SerialPort(Protocol):
    """What is used of an open pyserial port, whichever class its URL opened: a device's
    ``serial.Serial`` or the classes of ``loop://``, ``socket://``, ``rfc2217://``, which
    share only pyserial's ``SerialBase`` (whose stubs leave these out)."""

    @property
    def in_waiting(self) -> int: ...
    @property
    def out_waiting(self) -> int: ...
    def read(self, size: int = 1) -> bytes: ...
    def write(self, b: bytes, /) -> int | None: ...
    def fileno(self) -> int: ...
    def close(self) -> None: ...


def split_device(url: str, baud: int) -> tuple[str, int]:
    """The path or pyserial URL to open, and the baud rate (``serial://PATH:BAUD`` wins)."""
    if not url.startswith(SCHEME):
        return url, baud
    path = url.removeprefix(SCHEME)
    head, sep, rate = path.rpartition(":")
    if sep and head and rate.isdigit() and int(rate) > 0:
        return head, int(rate)
    return path, baud


def open_problem(url: str, baud: int) -> str | None:
    """Why the device cannot be opened now (None: it can); it is closed again at once."""
    path, rate = split_device(url, baud)
    try:
        open_port(path, baudrate=rate, timeout=0).close()
    except _PORT_ERRORS as exc:
        text = str(getattr(exc, "strerror", None) or exc)
        # pyserial names the port twice ("could not open port P: [Errno 2] ...: 'P'"): once
        # is enough for a STATUSTEXT the operator reads.
        return text.removeprefix(f"could not open port {path}: ")
    return None


def open_port(path: str, **settings: Any) -> SerialPort:
    """Open a device path or pyserial URL with pyserial's settings (``baudrate``, ...).

    A device path opens with ``termios2_serial.port_class()``: pyserial 3.5 cannot reopen a
    port left at a custom rate (SBUS's 100000 8E2) by a process that crashed or was
    restarted, nor open one at all on glibc 2.42 (pyserial issue #805); see that module.
    """
    if "://" in path:
        return serial.serial_for_url(path, **settings)
    return port_class()(path, **settings)


def _read_port(port: SerialPort, now_us: Callable[[], int], size: int) -> tuple[bytes, int]:
    """Any pyserial port (socket://, loop://): the first byte, the time, then the rest."""
    # pyserial's read(size) waits until size bytes or the timeout: at 4800 baud that
    # would hold every sentence back by the whole timeout and blur its time stamp.
    # So wait for one byte, then take only what is already there.
    data = port.read(1)
    t_us = now_us()
    # Only what is there now: more may arrive while reading, and in lockstep that
    # is the simulator's next frame, which this stamp does not belong to.
    if data and size > 1 and (waiting := port.in_waiting):
        data += port.read(min(waiting, size - 1))
    return data, t_us


# How long a read waits for a first byte. Every empty return wakes the plug-in for nothing
# (a silent device on the bench woke six sensor processes five times a second at 0.2 s);
# the bound is how fast a plug-in told to stop notices, well inside the supervisor's
# grace before SIGKILL (exec_control/supervisor.py, STOP_GRACE_S).
READ_TIMEOUT_S = 1.0  # a silent device: the caller's step (and status) once a second
WRITE_TIMEOUT_S = 0.5


class ReopeningSerial:
    """A port that is opened on first use and reopened, with back-off, whenever it fails."""

    def __init__(
        self,
        url: str,
        baud: int = 9600,
        read_timeout_s: float = READ_TIMEOUT_S,
        framing: Mapping[str, Any] | None = None,
        stop_fd: int | None = None,
        low_latency: bool = False,
    ) -> None:
        self.url = url
        self.stop_fd = stop_fd
        # Ask the driver to hand each byte over at once (``set_low_latency``) at every open.
        self.low_latency_wanted = low_latency
        self.low_latency = False  # the driver took it at the last open
        self.framing = dict(framing or {})  # pyserial's parity/stopbits/bytesize, if not 8N1
        self.path, self.baud = split_device(url, baud)
        self.read_timeout_s = read_timeout_s
        self.reopens = 0  # times the device was lost and reopening began
        self.open_failures = 0  # failed attempts to open
        self.opens = 0  # successful opens, the first included
        self.bytes_in = 0
        self.bytes_out = 0
        self._port: SerialPort | None = None
        self._fd: int | None = None  # a device's descriptor, read and written directly
        self._poll: select.poll | None = None  # on _fd (and stop_fd)
        self._wake: WakeBytes | None = None  # _fd's VMIN, when a reader asked for one
        self._timeout_ms = max(0, round(read_timeout_s * 1000))
        self._retry_s = FIRST_RETRY_S
        self._next_try = 0.0  # time.monotonic() of the next open attempt
        self._closed = threading.Event()  # set by close(): ends any back-off wait at once

    @property
    def is_open(self) -> bool:
        """Whether the device is open now."""
        return self._port is not None

    def wake_after(self, n_bytes: int) -> None:
        """Let the next reads wait until ``n_bytes`` have come (1 to 255, termios VMIN;
        ``companion.sensors.tty_wake``), not only the first: for a caller with work only
        every few frames. A port without a descriptor, or reopened and not asked again,
        wakes at the first byte."""
        if self._fd is None:
            return
        if self._wake is None:
            if n_bytes <= 1:
                return
            self._wake = WakeBytes(self._fd)
        self._wake.set(n_bytes)

    def read(self, size: int = 4096) -> bytes:
        """What has arrived, up to ``size`` bytes; waits at most the read timeout for the
        first byte and returns b"" when none came."""
        return self.read_stamped(lambda: 0, size)[0]

    def read_stamped(self, now_us: Callable[[], int], size: int = 4096) -> tuple[bytes, int]:
        """As ``read``, with ``now_us()`` taken when the first byte arrived.

        The time is taken before the rest is read, and only the bytes already there then are
        read: in a lockstep simulation the bytes still unread hold the simulator at the
        frame that sent them, so the stamp is that frame's time however late the reader
        runs (and on hardware, the first byte is the closest to when the sentence was sent).
        """
        port = self._ensure_open(wait=True)
        if port is None or size <= 0:
            return b"", now_us()
        try:
            if self._fd is not None:
                data, t_us = self._read_fd(self._fd, now_us, size)
            else:
                data, t_us = _read_port(port, now_us, size)
        except _PORT_ERRORS as exc:
            self._lost(exc)
            return b"", now_us()
        self.bytes_in += len(data)
        return data, t_us

    def _read_fd(self, fd: int, now_us: Callable[[], int], size: int) -> tuple[bytes, int]:
        """A device with a file descriptor: one poll, then what is there, in one read.

        What pyserial's read(1), in_waiting and read(n) do in five system calls and
        several Python calls, for every sentence of a 100 Hz device.
        """
        assert self._poll is not None
        events = self._poll.poll(self._timeout_ms)
        if not events:
            return b"", now_us()
        if self.stop_fd is not None and _polled(events, self.stop_fd):
            drain(self.stop_fd)  # a signal: its handler has run; the caller looks now
            return b"", now_us()
        t_us = now_us()
        try:
            data = os.read(fd, size)
        except (BlockingIOError, InterruptedError):
            return b"", t_us  # readable a moment ago, taken by nobody else: try again
        if not data:  # pyserial's own verdict on a readable device with nothing to read
            raise serial.SerialException("device reports readiness to read but returned no data")
        if self._wake is not None:
            data = self._wake.read_rest(data, size)
        return data, t_us

    def write(self, data: bytes) -> int:
        """Bytes written; 0 when the device is gone (it is reopened later) or too slow.

        Blocks at most the write timeout (0.5 s, or the read timeout if shorter). After a
        write timeout some bytes may have gone out: pyserial does not say how many.
        """
        port = self._ensure_open(wait=False)
        if port is None:
            return 0
        try:
            written = (
                _write_fd(self._fd, port, data) if self._fd is not None else port.write(data) or 0
            )
        except serial.SerialTimeoutException:
            log.debug("%s: write timed out", self.url)
            return 0
        except _PORT_ERRORS as exc:
            self._lost(exc)
            return 0
        self.bytes_out += written
        return written

    def out_waiting(self) -> int:
        """Bytes written but not yet gone out on the wire (0 when closed or unknown)."""
        port = self._port
        if port is None:
            return 0
        try:
            if self._fd is not None:
                queued = fcntl.ioctl(self._fd, _TIOCOUTQ, _UINT_ZERO)
                return int.from_bytes(queued, sys.byteorder)
            return int(port.out_waiting)
        except (*_PORT_ERRORS, AttributeError, NotImplementedError):
            return 0

    def close(self) -> None:
        """Close the device; a later read or write opens it again."""
        self._closed.set()
        self._drop_port()

    def _ensure_open(self, wait: bool) -> SerialPort | None:
        if self._port is not None:
            return self._port
        self._closed.clear()
        delay = self._next_try - time.monotonic()
        if delay > 0:
            if wait:  # back-off, bounded so the caller gets control back regularly
                self._closed.wait(min(delay, self.read_timeout_s))
            return None
        try:
            # A bounded write timeout, not 0: pyserial's non-blocking write retries EAGAIN in
            # a busy loop while the device's buffer is full.
            port = open_port(
                self.path,
                baudrate=self.baud,
                timeout=self.read_timeout_s,
                write_timeout=min(self.read_timeout_s, WRITE_TIMEOUT_S),
                **self.framing,
            )
        except _PORT_ERRORS as exc:
            self.open_failures += 1
            # Warn once per outage; the retries after it would only repeat the news.
            level = logging.WARNING if self._retry_s == FIRST_RETRY_S else logging.DEBUG
            log.log(level, "cannot open %s: %s (retrying)", self.url, exc)
            self._next_try = time.monotonic() + self._retry_s
            self._retry_s = min(2 * self._retry_s, MAX_RETRY_S)
            return None
        log.info("opened %s at %d baud", self.url, self.baud)
        if self.low_latency_wanted:
            self.low_latency = set_low_latency(port, self.url)
        self.opens += 1
        self._retry_s = FIRST_RETRY_S
        self._port = port
        self._fd = _descriptor(port)
        self._poll = _poll_for(self._fd, self.stop_fd) if self._fd is not None else None
        return port

    def _lost(self, exc: BaseException) -> None:
        log.warning("%s vanished (%s): reopening", self.url, exc)
        self.reopens += 1
        self._drop_port()
        self._next_try = time.monotonic() + self._retry_s

    def _drop_port(self) -> None:
        port, self._port, self._fd, self._poll = self._port, None, None, None
        self._wake = None  # a reopened port starts at pyserial's VMIN of 1
        if port is not None:
            try:
                port.close()
            except _PORT_ERRORS:
                pass  # already gone; nothing more to release


def set_low_latency(port: object, url: str) -> bool:
    """Ask the port's driver for low latency (``ASYNC_LOW_LATENCY``, pyserial's
    ``set_low_latency_mode``); whether it took it.

    Linux's FTDI driver then sets the adapter's latency timer from 16 ms to 1 ms. At 16 ms
    the adapter holds what it received until it has 62 bytes or the timer runs out, so a
    100 Hz IMU's sentences reach the board late by several milliseconds and in lumps, and
    each is stamped that late. A pty, a socket or a driver without the setting refuses it,
    which costs nothing.
    """
    ask = getattr(port, "set_low_latency_mode", None)
    if ask is None:
        return False
    try:
        ask(True)
    except (ValueError, OSError, NotImplementedError) as exc:
        log.debug("%s: no low-latency mode (%s)", url, exc)
        return False
    log.info("%s: low-latency mode on", url)
    return True


def _write_fd(fd: int, port: SerialPort, data: bytes) -> int:
    """Straight to the descriptor; what does not fit at once goes through pyserial, which
    waits for room up to the write timeout (it also waits, with a select, after a write
    that fitted)."""
    try:
        written = os.write(fd, data)
    except BlockingIOError:
        written = 0
    if written == len(data):
        return written
    return written + (port.write(data[written:]) or 0)


def _polled(events: list[tuple[int, int]], fd: int) -> bool:
    """Whether ``fd`` is among a poll's events (a loop: ``any`` over a generator cost more,
    at every read of a 100 Hz device)."""
    for ready, _ in events:  # noqa: SIM110 - the loop is the point
        if ready == fd:
            return True
    return False


def _descriptor(port: SerialPort) -> int | None:
    """The port's descriptor when it is a POSIX serial port (or pty), else None."""
    fd = getattr(port, "fd", None)
    return fd if isinstance(port, serial.Serial) and isinstance(fd, int) else None


def _poll_for(fd: int, stop_fd: int | None) -> select.poll:
    """A poll on a device's descriptor (and ``stop_fd``)."""
    poll = select.poll()
    poll.register(fd, select.POLLIN)
    if stop_fd is not None:
        poll.register(stop_fd, select.POLLIN)
    return poll
