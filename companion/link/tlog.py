"""``.tlog`` recording: every frame in and out, as MAVProxy and QGroundControl write it.

The format is a sequence of (8-byte big-endian microseconds since 1970, raw MAVLink
frame), which pymavlink's mavlogfile, MAVExplorer and QGroundControl replay.
"""

from __future__ import annotations

import logging
import struct
import time
from pathlib import Path

log = logging.getLogger(__name__)
FLUSH_PERIOD_S = 0.5


class TlogWriter:
    """Appends frames with their wall-clock time stamps."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file = self.path.open("ab", buffering=64 * 1024)
        self.frames = 0
        self._flushed = time.monotonic()

    def write(self, frame: bytes, unix_us: int | None = None) -> None:
        stamp = time.time_ns() // 1000 if unix_us is None else unix_us
        try:
            self._file.write(struct.pack(">Q", stamp) + frame)
            self.frames += 1
            if time.monotonic() - self._flushed > FLUSH_PERIOD_S:
                self._file.flush()  # a crash loses at most this much of the recording
                self._flushed = time.monotonic()
        except OSError as exc:  # a full disk must not take the link down
            log.warning("tlog %s: %s", self.path, exc)

    def close(self) -> None:
        self._file.close()
