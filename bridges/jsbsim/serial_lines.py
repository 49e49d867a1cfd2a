"""Real serial lines for hardware in the loop: the emulated devices on ports a user names.

``companion hil`` writes each device's bytes to a line the user wires to the vehicle's
computer (a USB-serial adapter, a UART, a pty pair from ``socat``, any pyserial URL) and
reads the servo card's bytes back from another. A line is named as one of:

- ``/dev/ttyUSB0`` or ``/dev/ttyUSB0:4800``: a serial port, at the device's usual rate
  unless a rate follows the last colon (also ``serial:///dev/ttyUSB0:4800``);
- ``pty:PATH``: a pseudo-terminal made here, reachable at ``PATH`` for a vehicle on the
  same machine (the link goes when the simulator ends);
- any other pyserial URL (``socket://host:port``, ``rfc2217://host:port``), at the
  device's usual rate.

Writes never wait for a slow line: what the line cannot take now is dropped and counted,
as a receiver's UART overruns, so one slow device cannot hold the physics back.
"""

from __future__ import annotations

import logging
import os

import serial

from bridges.jsbsim.ptys import PtyPort

log = logging.getLogger(__name__)

# The rates the shipped configs' drivers use (companion/configs/sim.toml), so a line
# named without a rate matches a vehicle configured as shipped.
DEFAULT_BAUD = {
    "gps": 38400,
    "compass": 19200,
    "imu": 115200,
    "rc": 100000,
    "battery": 57600,
    "range": 115200,
    "servos": 9600,
}
# SBUS is 8 data bits, even parity, two stop bits; every other device 8N1.
FRAMING = {"rc": (serial.PARITY_EVEN, serial.STOPBITS_TWO)}
PTY_PREFIX = "pty:"


class SerialLine:
    """One real serial line, with the interface of the simulator's ptys."""

    def __init__(self, name: str, url: str, baud: int) -> None:
        parity, stopbits = FRAMING.get(name, (serial.PARITY_NONE, serial.STOPBITS_ONE))
        self.name, self.path, self.baud = name, url, baud
        # timeout 0 and write_timeout 0: neither read nor write ever waits.
        self.port = serial.serial_for_url(
            url, baudrate=baud, parity=parity, stopbits=stopbits, timeout=0, write_timeout=0
        )
        # The servo card's line brings the board's commands back: on a USB adapter they
        # would come in lumps at its 16 ms latency timer, a late control loop in the loop.
        # (The vehicle asks the same of its IMU's port; a pty refuses, which changes nothing.)
        try:
            self.port.set_low_latency_mode(True)
        except (AttributeError, ValueError, OSError, NotImplementedError):
            pass
        self.bytes_out = 0
        self.dropped = 0

    def write(self, data: bytes) -> None:
        """Send what the line takes now; drop and count the rest."""
        fd = getattr(self.port, "fd", None)
        try:
            # pyserial 3.5's write with write_timeout 0 spins on a full line (it retries
            # EAGAIN forever), so a port with a descriptor (opened non-blocking) is
            # written directly; URL ports (sockets) go through pyserial.
            sent = os.write(fd, data) if fd is not None else self.port.write(data) or 0
        except (BlockingIOError, serial.SerialTimeoutException):
            sent = 0
        except (OSError, serial.SerialException) as exc:
            log.warning("%s line %s: %s", self.name, self.path, exc)
            sent = 0
        self.bytes_out += sent
        self.dropped += len(data) - sent

    def read(self) -> bytes:
        """What the vehicle wrote towards the device, without waiting."""
        try:
            return bytes(self.port.read(max(self.port.in_waiting, 1)))
        except serial.SerialException as exc:
            log.warning("%s line %s: %s", self.name, self.path, exc)
            return b""

    def unread(self) -> int:
        """Unknown on a real line: the far end's buffer is not ours to ask (lockstep is off)."""
        return 0

    def close(self) -> None:
        """Release the port."""
        self.port.close()


def split_line(name: str, spec: str) -> tuple[str, int]:
    """A line's pyserial URL and rate, from how the user named it."""
    baud = DEFAULT_BAUD.get(name, 9600)
    url = spec.removeprefix("serial://")
    if "://" in url:
        return url, baud
    path, sep, rate = url.rpartition(":")
    if sep and rate.isdigit():
        if int(rate) <= 0:
            raise ValueError(f"{name}: the rate in {spec!r} must be positive")
        return path, int(rate)
    return url, baud


def open_line(name: str, spec: str) -> PtyPort | SerialLine:
    """Open the line ``spec`` names for device ``name``; a ValueError says what is wrong."""
    if spec.startswith(PTY_PREFIX):
        path = spec.removeprefix(PTY_PREFIX)
        if not path:
            raise ValueError(f"{name}: pty: needs a path for the link, e.g. pty:/tmp/hil/{name}")
        return PtyPort(name, link=path)
    url, baud = split_line(name, spec)
    try:
        return SerialLine(name, url, baud)
    except (serial.SerialException, OSError) as exc:
        raise ValueError(f"{name}: cannot open {url} at {baud} baud: {exc}") from None
