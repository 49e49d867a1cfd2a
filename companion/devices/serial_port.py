"""A serial device that comes back: read and write never raise, a vanished device is reopened.

Accepts ``serial:///dev/ttyUSB0:4800`` (our form, baud in the URL), a plain device or pty
path, and any pyserial URL (``socket://host:port``, ``loop://``).
"""

from __future__ import annotations

import logging
import threading

import serial

log = logging.getLogger(__name__)
FIRST_RETRY_S = 0.1
MAX_RETRY_S = 2.0


def split_device(url: str, baud: int) -> tuple[str, int]:
    """The pyserial URL or path, and the baud rate (from ``serial://...:BAUD`` if given)."""
    if url.startswith("serial://"):
        path, sep, rate = url.removeprefix("serial://").rpartition(":")
        if sep and rate.isdigit() and path:
            return path, int(rate)
        return url.removeprefix("serial://"), baud
    return url, baud


class ReopeningSerial:
    """Reads block at most ``read_timeout_s``; failures close the port and retry later."""

    def __init__(self, url: str, baud: int = 9600, read_timeout_s: float = 0.2) -> None:
        self.url, self.baud = split_device(url, baud)
        self.read_timeout_s = read_timeout_s
        self.port: serial.SerialBase | None = None
        self.reopens = 0
        self.open_failures = 0
        self.bytes_in = 0
        self.bytes_out = 0
        self._retry_s = FIRST_RETRY_S
        self._wait = threading.Event()

    def _open(self) -> bool:
        if self.port is not None:
            return True
        try:
            self.port = serial.serial_for_url(
                self.url, baudrate=self.baud, timeout=self.read_timeout_s, write_timeout=0
            )
        except (serial.SerialException, OSError, ValueError) as exc:
            self.open_failures += 1
            log.debug("cannot open %s: %s", self.url, exc)
            # Bounded by the read timeout so the caller's step() still returns regularly.
            self._wait.wait(min(self._retry_s, self.read_timeout_s))
            self._retry_s = min(self._retry_s * 2, MAX_RETRY_S)
            return False
        self._retry_s = FIRST_RETRY_S
        return True

    def _lost(self, exc: Exception) -> None:
        log.warning("%s vanished (%s): reopening", self.url, exc)
        self.reopens += 1
        if self.port is not None:
            try:
                self.port.close()
            except (serial.SerialException, OSError):
                pass
        self.port = None

    def read(self, size: int = 512) -> bytes:
        """Up to ``size`` bytes, waiting at most the read timeout; b"" when nothing came."""
        if not self._open():
            return b""
        try:
            data = self.port.read(size)  # type: ignore[union-attr]
        except (serial.SerialException, OSError, TypeError) as exc:
            self._lost(exc)
            return b""
        self.bytes_in += len(data)
        return data

    def write(self, data: bytes) -> int:
        """Bytes written (0 when the device is gone: it is reopened on the next call)."""
        if not self._open():
            return 0
        try:
            written = self.port.write(data) or 0  # type: ignore[union-attr]
        except serial.SerialTimeoutException:
            return 0
        except (serial.SerialException, OSError) as exc:
            self._lost(exc)
            return 0
        self.bytes_out += written
        return written

    def close(self) -> None:
        if self.port is not None:
            self.port.close()
            self.port = None
