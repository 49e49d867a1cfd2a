"""A pyserial port whose rate and framing are set by Linux's termios2 ioctl, so it reopens.

The work-around for pyserial 3.5's custom baud rates on Linux (pyserial issue #805, fixed
upstream by PR #808, not in a release yet). pyserial passes ``BOTHER`` as the speed to
``tcsetattr`` and sets the real rate afterwards with the ``TCSETS2`` ioctl. glibc refuses
that two ways:

- glibc 2.42 and newer take only the ``Bnnn`` constants in ``cfsetispeed``: every open at a
  custom rate (SBUS's 100000) fails with ``termios.error: (22, 'Invalid argument')``;
- older glibc (2.36 here) checks, after a ``tcsetattr`` that changed nothing, that the
  parity and character size it asked for stuck, and calls it ``EINVAL`` when they did not.
  A pty drops parity, and a port left at ``BOTHER`` by the last process (a crash, kill -9,
  a service restart) shows no change: the second open of a pty at 100000 8E2 fails.

So pyserial's own ``tcsetattr`` is given what every glibc takes and every tty keeps (8 bits,
no parity, the asked rate when it has a ``Bnnn`` constant, else 38400 as the upstream fix
does), and the rate, character size and parity are then set together by ``TCSETS2``, which
glibc never sees. Everything else (raw mode, stop bits, flow control, timeouts, the lock)
is pyserial's own. Drop this module once a pyserial release has PR #808 and a test shows
the second open of a pty at 100000 8E2 passing with plain ``serial.Serial``.

Where ``TCSETS2`` is not implemented (ENOSYS: qemu-user, the emulated arm64 board), the
rate and framing go through ``tcsetattr`` instead; a custom rate then stays at the
placeholder, with a warning (on a pty, as in hardware in the loop, the rate means nothing).
"""

from __future__ import annotations

import array
import errno
import fcntl
import logging
import sys
import termios

import serial
from serial.serialposix import PlatformSpecific

# ``struct termios2`` as x86, ARM and RISC-V Linux define it: four tcflag_t, c_line, 19 c_cc,
# then c_ispeed and c_ospeed; 11 unsigned ints (the ioctl numbers below encode 44 bytes).
_TERMIOS2_WORDS = 11
_CFLAG, _ISPEED, _OSPEED = 2, 9, 10
TCGETS2 = 0x802C542A
TCSETS2 = 0x402C542B
BOTHER = 0o010000
CMSPAR = 0o10000000000  # "stick" parity, for mark and space
_CHAR_SIZE = {5: termios.CS5, 6: termios.CS6, 7: termios.CS7, 8: termios.CS8}
_PARITY = {
    serial.PARITY_NONE: 0,
    serial.PARITY_EVEN: termios.PARENB,
    serial.PARITY_ODD: termios.PARENB | termios.PARODD,
    serial.PARITY_MARK: termios.PARENB | CMSPAR | termios.PARODD,
    serial.PARITY_SPACE: termios.PARENB | CMSPAR,
}
_CLEARED = termios.CBAUD | termios.CIBAUD | termios.CSIZE | termios.PARENB | termios.PARODD
PLACEHOLDER_BAUD = 38400  # what tcsetattr is given for a rate without a Bnnn constant
# The kernel's own CBAUD encoding of the standard rates (pyserial's Linux table), for
# TCSETS2: Python's ``termios.Bnnn`` are glibc's, which from 2.42 may be the rate itself.
_KERNEL_SPEED: dict[int, int] = dict(PlatformSpecific.BAUDRATE_CONSTANTS)

log = logging.getLogger(__name__)


def speed_constant(baud: int) -> int | None:
    """The ``Bnnn`` constant (glibc's, for tcsetattr) of a standard rate, None for a custom
    one."""
    return getattr(termios, f"B{baud}", None)


def apply_rate_and_framing(fd: int, baud: int, bytesize: int, parity: str) -> int:
    """Set the rate, character size and parity of the tty ``fd`` in one ``TCSETS2``;
    the c_cflag it was given. ValueError: a value no tty takes, or the ioctl failed."""
    if bytesize not in _CHAR_SIZE or parity not in _PARITY or baud <= 0:
        raise ValueError(f"invalid framing: {baud} baud, {bytesize} bits, parity {parity!r}")
    buf = array.array("I", [0] * _TERMIOS2_WORDS)
    try:
        fcntl.ioctl(fd, TCGETS2, buf)
        cflag = buf[_CFLAG] & ~(_CLEARED | CMSPAR)  # CIBAUD 0: input at the output's rate
        cflag |= _CHAR_SIZE[bytesize] | _PARITY[parity]
        cflag |= _KERNEL_SPEED.get(baud, BOTHER)
        buf[_CFLAG] = cflag
        buf[_ISPEED] = buf[_OSPEED] = baud
        fcntl.ioctl(fd, TCSETS2, buf)
    except OSError as exc:
        if exc.errno == errno.ENOSYS:  # an emulator without termios2
            return _apply_with_tcsetattr(fd, baud, bytesize, parity)
        raise ValueError(f"cannot set {baud} baud {bytesize}{parity}: {exc}") from exc
    return cflag


def _apply_with_tcsetattr(fd: int, baud: int, bytesize: int, parity: str) -> int:
    """The rate (a standard one; else the placeholder's stays), character size and parity
    through ``tcsetattr``; the c_cflag the tty then has."""
    attrs = termios.tcgetattr(fd)
    cflag = attrs[2] & ~(termios.CSIZE | termios.PARENB | termios.PARODD | CMSPAR)
    attrs[2] = cflag | _CHAR_SIZE[bytesize] | _PARITY[parity]
    speed = speed_constant(baud)
    if speed is None:
        log.warning("no termios2 here (an emulator?): %d baud left at %d", baud, PLACEHOLDER_BAUD)
    else:
        attrs[4] = attrs[5] = speed
    try:
        termios.tcsetattr(fd, termios.TCSANOW, attrs)
    except termios.error as exc:
        # glibc's check that parity stuck fails on a pty, which drops it: the port stays
        # as pyserial left it (8 bits, no parity), which is all a pty carries anyway.
        log.warning("no termios2 here: %d%s not set (%s); the port stays 8N", bytesize, parity, exc)
        return int(termios.tcgetattr(fd)[2])
    return int(attrs[2])


class Termios2Serial(serial.Serial):
    """``serial.Serial`` whose rate, character size and parity go through ``TCSETS2``."""

    # pyserial's private settings and _reconfigure_port, which types-pyserial leaves out.
    _baudrate: int
    _bytesize: int
    _parity: str

    def _reconfigure_port(self, force_update: bool = False) -> None:
        if self.fd is None:  # pyserial's own refusal
            super()._reconfigure_port(force_update)  # type: ignore[misc]
            return
        asked = (self._baudrate, self._bytesize, self._parity)
        if speed_constant(self._baudrate) is None:
            self._baudrate = PLACEHOLDER_BAUD
        self._bytesize, self._parity = serial.EIGHTBITS, serial.PARITY_NONE
        try:
            super()._reconfigure_port(force_update)  # type: ignore[misc]
        finally:
            self._baudrate, self._bytesize, self._parity = asked
        apply_rate_and_framing(self.fd, *asked)


def port_class() -> type[serial.Serial]:
    """The class a device path is opened with: the work-around on Linux only."""
    return Termios2Serial if sys.platform.startswith("linux") else serial.Serial
