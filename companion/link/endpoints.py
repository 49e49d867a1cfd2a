"""The vehicle's MAVLink endpoints, given as URLs, several at once.

``udpout://HOST:PORT`` sends to a ground station (and hears its replies on the same
socket), ``udpin://HOST:PORT`` listens and answers whoever speaks, ``tcpin://HOST:PORT``
accepts TCP clients, ``serial:///dev/ttyUSB0:57600`` is a radio modem (MAVProxy's and
MAVSDK's spellings of these are taken too: ``endpoint_urls``). Endpoints move
bytes only; framing is companion.link.codec's (one parser per remote), CRC and signing pymavlink's.
"""

from __future__ import annotations

import contextlib
import logging
import socket
import time
from abc import ABC, abstractmethod
from urllib.parse import urlparse

import serial

from companion.link.endpoint_urls import (
    SCHEME_NAMES,
    EndpointError,
    EndpointOptions,
    parse_serial_url,
    split_options,
)
from companion.sensors.serial_port import FIRST_RETRY_S, MAX_RETRY_S, SerialPort, open_port

log = logging.getLogger(__name__)
# What pyserial raises when a device is gone (TypeError: a port closed under a read).
_PORT_ERRORS = (serial.SerialException, OSError, ValueError, TypeError)

Remote = tuple[str, int] | str  # a UDP/TCP peer address, or the serial device
MAX_DATAGRAM = 65535


class Endpoint(ABC):
    """One transport. ``read_ready`` returns what arrived, keyed by the remote it came from."""

    options: EndpointOptions
    fd_changes = 0  # descriptors closed or opened so far (a number closed may come back)

    def __init__(self, url: str) -> None:
        self.url = url
        self.options = EndpointOptions()
        self.bytes_in = 0
        self.bytes_out = 0
        self.write_errors = 0

    @abstractmethod
    def filenos(self) -> list[int]:
        """File descriptors to wait on."""

    @abstractmethod
    def read_ready(self, fd: int) -> list[tuple[Remote, bytes]]:
        """Read what is waiting on ``fd`` (never blocks)."""

    @abstractmethod
    def send(self, data: bytes) -> int:
        """Send to every remote of this endpoint; never blocks, never raises."""

    @abstractmethod
    def close(self) -> None:
        """Release the transport."""

    def has_remote(self) -> bool:
        """True when there is someone to send to."""
        return True


def _host_port(url: str) -> tuple[str, int]:
    parsed = urlparse(url)
    if not parsed.hostname or parsed.port is None:
        raise EndpointError(f"{url!r}: expected SCHEME://HOST:PORT")
    return parsed.hostname, parsed.port


class UdpOut(Endpoint):
    """Sends to a fixed address (a ground station); its replies come back to our port."""

    def __init__(self, url: str) -> None:
        super().__init__(url)
        self.target = _host_port(url)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setblocking(False)
        self.sock.bind(("0.0.0.0", 0))

    def filenos(self) -> list[int]:
        return [self.sock.fileno()]

    def read_ready(self, fd: int) -> list[tuple[Remote, bytes]]:
        out: list[tuple[Remote, bytes]] = []
        while True:
            try:
                data, addr = self.sock.recvfrom(MAX_DATAGRAM)
            except (BlockingIOError, InterruptedError):
                return out
            except OSError:  # ICMP port unreachable while nobody listens: not an error
                return out
            self.bytes_in += len(data)
            out.append((addr, data))

    def send(self, data: bytes) -> int:
        try:
            sent = self.sock.sendto(data, self.target)
        except OSError:
            self.write_errors += 1
            return 0
        self.bytes_out += sent
        return sent

    def close(self) -> None:
        self.sock.close()


class UdpIn(UdpOut):
    """Listens on an address and answers every remote that has spoken to it."""

    def __init__(self, url: str) -> None:
        Endpoint.__init__(self, url)
        self.remotes: list[tuple[str, int]] = []
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.setblocking(False)
        self.sock.bind(_host_port(url))

    def read_ready(self, fd: int) -> list[tuple[Remote, bytes]]:
        got = super().read_ready(fd)
        for addr, _ in got:
            if isinstance(addr, tuple) and addr not in self.remotes:  # (UDP: always a tuple)
                self.remotes.append(addr)
                log.info("%s: new remote %s:%d", self.url, *addr)
        return got

    def has_remote(self) -> bool:
        return bool(self.remotes)

    def send(self, data: bytes) -> int:
        sent = 0
        for addr in self.remotes:
            try:
                sent = self.sock.sendto(data, addr)
                self.bytes_out += sent
            except OSError:
                self.write_errors += 1
        return sent


class TcpIn(Endpoint):
    """Accepts TCP clients; each is a remote with its own byte stream."""

    def __init__(self, url: str) -> None:
        super().__init__(url)
        self.server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.server.bind(_host_port(url))
        self.server.listen(4)
        self.server.setblocking(False)
        self.clients: dict[int, socket.socket] = {}

    def filenos(self) -> list[int]:
        return [self.server.fileno(), *self.clients]

    def read_ready(self, fd: int) -> list[tuple[Remote, bytes]]:
        if fd == self.server.fileno():
            try:
                client, addr = self.server.accept()
            except OSError:
                return []
            client.setblocking(False)
            self.clients[client.fileno()] = client
            self.fd_changes += 1
            log.info("%s: client %s:%d connected", self.url, *addr)
            return []
        conn = self.clients.get(fd)
        if conn is None:
            return []
        try:
            data = conn.recv(MAX_DATAGRAM)
        except (BlockingIOError, InterruptedError):
            return []
        except OSError:
            data = b""
        if not data:
            self._drop(fd)
            return []
        self.bytes_in += len(data)
        return [(f"tcp{fd}", data)]

    def _drop(self, fd: int) -> None:
        conn = self.clients.pop(fd, None)
        if conn is not None:
            conn.close()
            self.fd_changes += 1

    def has_remote(self) -> bool:
        return bool(self.clients)

    def send(self, data: bytes) -> int:
        for fd, conn in list(self.clients.items()):
            try:
                self.bytes_out += conn.send(data)
            except (BlockingIOError, InterruptedError):
                self.write_errors += 1  # a slow client loses this frame, not the vehicle's time
            except OSError:
                self._drop(fd)
        return len(data)

    def close(self) -> None:
        for fd in list(self.clients):
            self._drop(fd)
        self.server.close()


class SerialEndpoint(Endpoint):
    """A radio modem or cable: ``serial:///dev/ttyUSB0:57600``.

    A device lost (a USB adapter pulled out: a read that fails, or readable with nothing to
    read) is closed, ``reopens`` counts it, and ``filenos`` opens it again when it is back,
    retrying after 0.1 s doubling to 2 s: the link's other endpoints fly on meanwhile. A
    device missing at start-up is waited for the same way (a radio unplugged, or one the
    kernel names a moment after the service started, must not take the UDP link down with
    it); ``companion check`` is where a wrong path shows.
    """

    def __init__(self, url: str) -> None:
        super().__init__(url)
        self.path, self.baud = parse_serial_url(url)
        self.reopens = 0
        self._retry_s = FIRST_RETRY_S
        self._next_try = 0.0
        self.port: SerialPort | None = None
        try:
            self.port = self._open()
        except _PORT_ERRORS as exc:
            log.warning("%s: cannot open (%s); waiting for it", url, exc)
            self._next_try = time.monotonic() + self._retry_s

    def _open(self) -> SerialPort:
        # open_port: a radio at a custom rate reopens after a restart (pyserial issue #805).
        return open_port(self.path, baudrate=self.baud, timeout=0, write_timeout=0)

    def filenos(self) -> list[int]:
        port = self.port if self.port is not None else self._reopen()
        return [port.fileno()] if port is not None else []

    def _reopen(self) -> SerialPort | None:
        now = time.monotonic()
        if now < self._next_try:
            return None
        try:
            self.port = self._open()
        except _PORT_ERRORS as exc:
            log.debug("%s: cannot reopen (%s)", self.url, exc)
            self._next_try = now + self._retry_s
            self._retry_s = min(2 * self._retry_s, MAX_RETRY_S)
            return None
        log.info("%s: reopened", self.url)
        self.fd_changes += 1
        self._retry_s = FIRST_RETRY_S
        return self.port

    def read_ready(self, fd: int) -> list[tuple[Remote, bytes]]:
        if self.port is None:
            return []
        try:
            data = self.port.read(4096)
        except _PORT_ERRORS as exc:  # pyserial: readable, yet nothing to read: it is gone
            self._lost(exc)
            return []
        self.bytes_in += len(data)
        return [(self.path, data)] if data else []

    def send(self, data: bytes) -> int:
        if self.port is None:
            self.write_errors += 1
            return 0
        try:
            sent = self.port.write(data) or 0
        except serial.SerialTimeoutException:
            self.write_errors += 1
            return 0
        except _PORT_ERRORS as exc:
            self.write_errors += 1
            self._lost(exc)
            return 0
        self.bytes_out += sent
        return sent

    def _lost(self, exc: BaseException) -> None:
        log.warning("%s vanished (%s): reopening", self.url, exc)
        self.reopens += 1
        self.close()
        self._next_try = time.monotonic() + self._retry_s

    def close(self) -> None:
        port, self.port = self.port, None
        if port is not None:
            self.fd_changes += 1
            with contextlib.suppress(*_PORT_ERRORS):
                port.close()


DEFAULT_NETWORK_BYTES_S = 1_000_000.0
SERIAL_SHARE = 0.8
KINDS: dict[str, type[Endpoint]] = dict(
    udpout=UdpOut, udpin=UdpIn, tcpin=TcpIn, serial=SerialEndpoint
)
assert sorted(KINDS) == sorted(SCHEME_NAMES)


def endpoint_problems(urls: list[str], signing_key: str) -> list[str]:
    """What is wrong with these endpoint URLs (the config check, before anything opens):
    an unknown scheme or option, signing asked for without a key."""
    problems = []
    for url in urls:
        try:
            _, options = split_options(str(url))
            if options.signing != "off" and not signing_key:
                problems.append(f"endpoint {url!r} asks for signing but signing_key is empty")
        except EndpointError as exc:
            problems.append(str(exc))
    return problems


def open_endpoint(url: str) -> Endpoint:
    """Open the endpoint a URL names; EndpointError for an unknown scheme or option."""
    base, options = split_options(url)
    endpoint = KINDS[base.split("://", 1)[0]](base)
    endpoint.options = options
    return endpoint


def default_budget(endpoint: Endpoint) -> float:
    """Bytes per second the endpoint may carry."""
    if endpoint.options.budget_bytes_s is not None:
        return endpoint.options.budget_bytes_s
    if isinstance(endpoint, SerialEndpoint):
        # 8N1 is ten bits a byte; keep a fifth of the wire free so the radio's buffer
        # drains and acknowledgements never wait behind a backlog.
        return endpoint.baud / 10.0 * SERIAL_SHARE
    return DEFAULT_NETWORK_BYTES_S


def open_endpoints(urls: list[str]) -> list[Endpoint]:
    """Every endpoint opened; RuntimeError naming the first that cannot be."""
    endpoints: list[Endpoint] = []
    for url in urls:
        try:
            endpoints.append(open_endpoint(url))
        except (EndpointError, OSError) as exc:
            raise RuntimeError(f"endpoint {url}: {exc}") from exc
    return endpoints


def serial_endpoints(urls: list[str]) -> list[tuple[str, int]]:
    """The serial endpoints' paths and baud rates (radios: devices ``companion check`` opens)."""
    bases = [split_options(str(url))[0] for url in urls]
    return [parse_serial_url(base) for base in bases if base.startswith("serial://")]
