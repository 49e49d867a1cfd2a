"""The navigation estimate CSV of the design (also the simulator's truth file).

Header ``t,roll,pitch,yaw,lat,lon,alt,vn,ve,vd``: seconds, radians (yaw in [-π, π] from
north), degrees, metres above MSL, m/s.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import TextIO

import numpy as np

COLUMNS = ("t", "roll", "pitch", "yaw", "lat", "lon", "alt", "vn", "ve", "vd")


class EstimateWriter:
    """Appends rows; close() flushes (a crash loses at most the buffer)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file: TextIO = self.path.open("w", buffering=1 << 16)
        self._file.write(",".join(COLUMNS) + "\n")
        self.rows = 0

    def add(
        self, t_s: float, roll: float, pitch: float, yaw: float, lat: float, lon: float,
        alt: float, vn: float, ve: float, vd: float,
    ) -> None:  # fmt: skip
        """One row."""
        yaw = math.remainder(yaw, math.tau)
        self._file.write(
            f"{t_s:.4f},{roll:.6f},{pitch:.6f},{yaw:.6f},{lat:.8f},{lon:.8f},{alt:.3f},"
            f"{vn:.4f},{ve:.4f},{vd:.4f}\n"
        )
        self.rows += 1

    def close(self) -> None:
        """Flush and close."""
        self._file.close()


def read_estimate(path: str | Path) -> dict[str, np.ndarray]:
    """An estimate (or truth) file as columns of floats."""
    with Path(path).open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    missing = [c for c in COLUMNS if rows and c not in rows[0]]
    if missing:
        raise ValueError(f"{path}: not an estimate file (no {', '.join(missing)})")
    return {c: np.array([float(r[c] or "nan") for r in rows]) for c in COLUMNS}
