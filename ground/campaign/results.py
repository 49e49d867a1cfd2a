"""The campaign's results table: one CSV row per flight, rewritten atomically after each.

A campaign killed halfway leaves a whole table of the flights done so far, so a rerun
skips them (``done_ids``) and flies only the rest.
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path
from typing import Any

NUMERIC = (
    "wind_n", "wind_e", "wind_d", "xtrack_rms_m", "xtrack_p95_m", "alt_rms_m",
    "airspeed_rms_m_s", "time_to_complete_s", "sim_s", "wall_s",
)  # fmt: skip
INTEGER = ("seed", "samples")


class ResultsTable:
    """Rows keyed by flight id, in the order they finished."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.rows: dict[str, dict[str, Any]] = {}
        if path.is_file():
            with path.open(newline="") as f:
                for row in csv.DictReader(f):
                    self.rows[row["flight_id"]] = _typed(row)

    def done_ids(self, retry_failed: bool = False) -> set[str]:
        """Flights that need not fly again."""
        return {k for k, r in self.rows.items() if not (retry_failed and r["status"] != "ok")}

    def add(self, row: dict[str, Any]) -> None:
        """Record a finished flight and write the table out."""
        self.rows[row["flight_id"]] = row
        self._write()

    def _write(self) -> None:
        columns: list[str] = []
        for row in self.rows.values():
            columns += [k for k in row if k not in columns]
        tmp = self.path.with_suffix(".csv.tmp")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with tmp.open("w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=columns)
            writer.writeheader()
            writer.writerows(self.rows.values())
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, self.path)


def _typed(row: dict[str, str]) -> dict[str, Any]:
    out: dict[str, Any] = dict(row)
    for key in NUMERIC:
        if key in out:
            out[key] = float(out[key]) if out[key] not in ("", None) else math.nan
    for key in INTEGER:
        if key in out and out[key] not in ("", None):
            out[key] = int(out[key])
    if "completed" in out:
        out["completed"] = out["completed"] == "True"
    return out
