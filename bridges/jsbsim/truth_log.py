"""The simulator's true state as a CSV in the design's estimate format."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TextIO

from bridges.jsbsim.fdm import TrueState

HEADER = "t,roll,pitch,yaw,lat,lon,alt,vn,ve,vd\n"


class TruthLog:
    """Appends one row a frame; flushed on close (and by the OS on a crash)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file: TextIO = self.path.open("w", buffering=1 << 16)
        self._file.write(HEADER)
        self.rows = 0

    def add(self, s: TrueState) -> None:
        """One row: angles in radians, yaw in [-π, π], lat/lon in degrees, alt MSL."""
        yaw = math.remainder(s.yaw, math.tau)
        self._file.write(
            f"{s.t_s:.4f},{s.roll:.6f},{s.pitch:.6f},{yaw:.6f},{s.lat_deg:.8f},"
            f"{s.lon_deg:.8f},{s.alt_msl_m:.3f},{s.vn:.4f},{s.ve:.4f},{s.vd:.4f}\n"
        )
        self.rows += 1

    def close(self) -> None:
        """Flush and close."""
        self._file.close()
