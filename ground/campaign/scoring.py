"""How well a flight followed its plan, from the simulator's truth: the campaign's score.

The samples are those the per-leg figures take (ground/campaign/legs.py, which the
tracking benchmarks and tests print): each waypoint-to-waypoint leg as flown, DO_JUMP
loops unrolled, on its straight part (more than 500 m from either corner), pooled over
the legs. Cross-track, height (from the leg's altitude) and airspeed errors are taken over
those samples. Airspeed is the truth's ground velocity less the steady wind the flight was
given (the truth file has no airspeed column; turbulence is left in, as a pitot would see
it).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from companion.control.mission.items import MissionItem
from companion.control.mission.plan import checked_plan
from ground.campaign.legs import airframe_defaults, flight_legs

COLUMNS = ("roll", "yaw", "lat", "lon", "alt", "vn", "ve", "vd")  # of the truth, those read


@dataclass
class TrackScore:
    """The figures of one flight (NaN where there were no straight-leg samples)."""

    xtrack_rms_m: float
    xtrack_p95_m: float
    alt_rms_m: float
    airspeed_rms_m_s: float
    samples: int

    def as_row(self) -> dict[str, float]:
        return asdict(self)


def score_track(
    truth: dict[str, np.ndarray] | dict[str, list[float]],
    plan: Path | list[MissionItem],
    airframe: str,
    wind_ned: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> TrackScore:
    """Cross-track, height and airspeed errors on the straight parts of the legs flown."""
    items = checked_plan(plan)[0] if isinstance(plan, Path) else plan
    columns = {k: np.asarray(truth[k], dtype=float) for k in COLUMNS}
    if len(columns["lat"]) == 0:
        return TrackScore(math.nan, math.nan, math.nan, math.nan, 0)
    vel = np.column_stack([columns[k] for k in ("vn", "ve", "vd")])
    speed = np.linalg.norm(vel - np.asarray(wind_ned, dtype=float), axis=1)
    cruise = airframe_defaults(airframe)["AIRSPEED_CRUISE"]
    xt, dz, dv = [], [], []
    for track in (figures.track for figures in flight_legs(columns, items, airframe, wind_ned)):
        on = track.straight()
        rows = slice(track.i0, track.i1)
        xt.append(np.abs(track.cross[on]))
        dz.append(columns["alt"][rows][on] - track.leg.alt_msl)
        dv.append(speed[rows][on] - cruise)
    cross = np.concatenate(xt) if xt else np.array([])
    if len(cross) == 0:
        return TrackScore(math.nan, math.nan, math.nan, math.nan, 0)
    height, airspeed = np.concatenate(dz), np.concatenate(dv)
    return TrackScore(
        float(np.sqrt(np.mean(cross**2))),
        float(np.percentile(cross, 95)),
        float(np.sqrt(np.mean(height**2))),
        float(np.sqrt(np.mean(airspeed**2))),
        len(cross),
    )
