"""The simulator's true state as a CSV in the design's estimate format.

Columns ``t,roll,pitch,yaw,lat,lon,alt,vn,ve,vd``: seconds, radians (yaw in [-π, π] from
north), degrees, metres above MSL, m/s (DESIGN.md). Written here rather than with the
navigator's writer, so the truth and the estimate it judges come from separate code.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TextIO

from bridges.sensor_models.true_state import TrueState

HEADER = "t,roll,pitch,yaw,lat,lon,alt,vn,ve,vd\n"


class TruthLog:
    """One row a frame; close() flushes (a crash loses at most the buffer)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file: TextIO = self.path.open("w", buffering=1 << 16)
        self._file.write(HEADER)
        self.rows = 0

    def add_state(self, s: TrueState) -> None:
        """The true state as a row."""
        yaw = math.remainder(s.yaw, math.tau)
        self._file.write(
            f"{s.t_s:.4f},{s.roll:.6f},{s.pitch:.6f},{yaw:.6f},{s.lat_deg:.8f},"
            f"{s.lon_deg:.8f},{s.alt_msl_m:.3f},{s.vn:.4f},{s.ve:.4f},{s.vd:.4f}\n"
        )
        self.rows += 1

    def close(self) -> None:
        """Flush and close."""
        self._file.close()


def wheels_path(truth_path: str | Path) -> Path:
    """Where the wheel contacts of a truth file are written: beside it, ``NAME_wheels.csv``."""
    truth_path = Path(truth_path)
    return truth_path.with_name(f"{truth_path.stem}_wheels.csv")


class WheelLog:
    """When the wheels took and lost the aircraft's weight, by simulation time: a row
    ``t,on_wheels`` (1 or 0) at the first frame and at each change. JSBSim's own contact
    is what a landing is judged by: the centre of gravity's height cannot tell a wheel
    skimming 0.3 m above the runway from one rolling on it."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        # Line-buffered: rows are few, and a reader of a flight still running sees them all.
        self._file: TextIO = self.path.open("w", buffering=1)
        self._file.write("t,on_wheels\n")
        self._last: bool | None = None

    def add(self, t_s: float, on_wheels: bool) -> None:
        """The contact at this frame (written when it changed)."""
        if on_wheels != self._last:
            self._file.write(f"{t_s:.4f},{int(on_wheels)}\n")
            self._last = on_wheels

    def close(self) -> None:
        """Flush and close."""
        self._file.close()


class ServoLog:
    """The surface commands the simulated servos received, by simulation time: one row each
    time the servo card got bytes, ``t,aileron,elevator,rudder,throttle`` (stick convention,
    empty when that servo was not among them)."""

    SURFACES = ("aileron", "elevator", "rudder", "throttle")

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file: TextIO = self.path.open("w", buffering=1 << 16)
        self._file.write("t," + ",".join(self.SURFACES) + "\n")

    def add(self, t_s: float, controls: dict[str, float]) -> None:
        """One delivery of servo bytes."""
        values = [f"{controls[k]:.4f}" if k in controls else "" for k in self.SURFACES]
        self._file.write(f"{t_s:.4f}," + ",".join(values) + "\n")

    def close(self) -> None:
        """Flush and close."""
        self._file.close()
