"""The simulator's true state as a CSV in the design's estimate format."""

from __future__ import annotations

from companion.navigation.estimate_csv import EstimateWriter
from ground.simulation.true_state import TrueState


class TruthLog(EstimateWriter):
    """One row a frame."""

    def add_state(self, s: TrueState) -> None:
        """The true state as a row of the estimate format."""
        self.add(s.t_s, s.roll, s.pitch, s.yaw, s.lat_deg, s.lon_deg, s.alt_msl_m, s.vn, s.ve, s.vd)
