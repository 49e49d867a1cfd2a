"""Log download as QGroundControl's Log Download page does it (LogDownloadController).

List: LOG_REQUEST_LIST 0..0xffff, entries collected by id. Download: the log in chunks of
512 bins of 90 bytes; a whole chunk is asked for at once, and when nothing arrives for
half a second the first hole of the chunk is asked for again; the next chunk once the
current one is full. Packets out of the current chunk or misaligned are ignored, as QGC
ignores them. ``drop`` loses chosen packets on arrival, as a lossy radio would.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tests.protocol.mav_client import GroundStation
from tests.support.vehicle import wait_for

if TYPE_CHECKING:
    from tests.protocol.test_mavproxy import MavProxy

log = logging.getLogger(__name__)

BIN = 90
TABLE_BINS = 512
CHUNK = BIN * TABLE_BINS
TIMEOUT_S = 0.5


def mavproxy_download(
    mavproxy: MavProxy, folder: Path, online: Callable[[], object], size: int, download_s: float
) -> bytes:
    """MAVProxy's ``log list`` and ``log download 0 flight.ulg`` (into ``folder``, where it
    runs) once
    ``online()`` has returned; the file's bytes. MAVProxy is closed and its output logged;
    it must have listed the log at ``size`` bytes."""
    try:
        online()
        mavproxy.type("log list")
        wait_for(lambda: "numLogs 1" in "".join(mavproxy.lines), 30, "the log listed")
        mavproxy.type("log download 0 flight.ulg")
        done = "Finished downloading"
        wait_for(lambda: done in "".join(mavproxy.lines), download_s, "the download")
    finally:
        output = mavproxy.close()
        log.info("MAVProxy said:\n%s", output[-3000:])
    assert f"size {size}" in output
    return (folder / "flight.ulg").read_bytes()


def list_logs(gcs: GroundStation, timeout_s: float = 10.0) -> dict[int, Any]:
    """Every LOG_ENTRY by id (empty when the vehicle has no log)."""
    gcs.mav.log_request_list_send(1, 1, 0, 0xFFFF)
    entries: dict[int, Any] = {}
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        msg = gcs.conn.recv_match(type="LOG_ENTRY", blocking=True, timeout=0.2)
        if msg is None:
            continue
        if msg.num_logs == 0:
            return {}
        entries[msg.id] = msg
        if len(entries) == msg.num_logs:
            return entries
    raise AssertionError(f"log list incomplete: {sorted(entries)}")


class QgcDownload:
    """One log downloaded the way QGroundControl does."""

    def __init__(
        self, gcs: GroundStation, log_id: int, size: int, drop: Callable[[int], bool] | None = None
    ) -> None:
        self.gcs, self.log_id, self.size = gcs, log_id, size
        self.drop = drop or (lambda ofs: False)
        self.data = bytearray(size)
        self.chunk = 0
        self.table = [False] * self._bins()
        self.requests = 0
        self.dropped = 0

    def _bins(self) -> int:
        return min(TABLE_BINS, math.ceil((self.size - self.chunk * CHUNK) / BIN))

    def _ask(self, ofs: int, count: int) -> None:
        self.requests += 1
        self.gcs.mav.log_request_data_send(1, 1, self.log_id, ofs, count)

    def _complete(self) -> bool:
        return all(self.table) and self.chunk + 1 == math.ceil(self.size / CHUNK)

    def _find_missing(self) -> None:
        if all(self.table):
            self.chunk += 1
            self.table = [False] * self._bins()
        start = self.table.index(False)
        end = next((i for i in range(start, len(self.table)) if self.table[i]), len(self.table))
        self._ask(self.chunk * CHUNK + start * BIN, (end - start) * BIN)

    def _receive(self, msg: Any) -> None:
        if msg.id != self.log_id or msg.ofs % BIN or msg.ofs > self.size:
            return
        if msg.ofs // CHUNK != self.chunk:
            return
        if self.drop(msg.ofs):
            self.dropped += 1
            return
        b = (msg.ofs - self.chunk * CHUNK) // BIN
        if b < len(self.table):
            self.table[b] = True
        self.data[msg.ofs : msg.ofs + msg.count] = bytes(msg.data[: msg.count])
        if self._complete():
            return
        if all(self.table):
            self.chunk += 1
            self.table = [False] * self._bins()
            self._ask(self.chunk * CHUNK, len(self.table) * BIN)
        elif b + 1 < len(self.table) and self.table[b + 1]:
            self._find_missing()  # the end of a hole just filled: the next one

    def run(self, timeout_s: float = 120.0) -> bytes:
        """Download the whole log; its bytes."""
        self._ask(0, len(self.table) * BIN)
        deadline = time.monotonic() + timeout_s
        while not self._complete():
            assert time.monotonic() < deadline, f"download stuck in chunk {self.chunk}"
            msg = self.gcs.conn.recv_match(type="LOG_DATA", blocking=True, timeout=TIMEOUT_S)
            if msg is None:
                self._find_missing()
            else:
                self._receive(msg)
        self.gcs.mav.log_request_end_send(1, 1)
        return bytes(self.data)
