"""A UDP hop between a ground station and the vehicle's ``udpin`` endpoint that loses the
vehicle's packets a test names, once each, as a radio (or a full receive buffer) would.

The ground station sends to ``port``; the hop sends on to the vehicle from a socket of its
own, and the vehicle's answers come back through it. Each datagram from the vehicle is
parsed and sent on without the frames ``drop`` says to lose.
"""

from __future__ import annotations

import select
import socket
import threading
from collections.abc import Callable
from typing import Any

from mavlink_dialect import companion as m


class LossyHop:
    """Relays both ways until closed, losing vehicle frames for which ``drop(msg)`` is true."""

    def __init__(self, vehicle_port: int, drop: Callable[[Any], bool]) -> None:
        self.drop = drop
        self.dropped = 0
        self._station = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._station.bind(("127.0.0.1", 0))
        self.port: int = self._station.getsockname()[1]
        self._vehicle = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._vehicle.connect(("127.0.0.1", vehicle_port))
        self._parser = m.MAVLink(None)
        self._station_addr: tuple[str, int] | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        sockets = [self._station, self._vehicle]
        while not self._stop.is_set():
            ready, _, _ = select.select(sockets, [], [], 0.1)
            if self._station in ready:
                data, self._station_addr = self._station.recvfrom(65536)
                self._vehicle.send(data)
            if self._vehicle in ready:
                data = self._vehicle.recv(65536)
                kept = self._kept(data)
                if kept and self._station_addr is not None:
                    self._station.sendto(kept, self._station_addr)

    def _kept(self, data: bytes) -> bytes:
        frames = self._parser.parse_buffer(data) or []
        kept = [f for f in frames if not self.drop(f)]
        self.dropped += len(frames) - len(kept)
        return b"".join(bytes(f.get_msgbuf()) for f in kept)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
        self._station.close()
        self._vehicle.close()
