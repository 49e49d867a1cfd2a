"""How well a flight followed its plan, from the simulator's truth.

Cross-track error is measured on the straight part of each waypoint-to-waypoint leg only:
past the turn onto it and before the turn off it (a margin of the turn radius at the
airframe's roll limit plus the L1 distance), since no controller can be on the line while
turning onto it. Height and airspeed errors are taken over the same samples. Airspeed is
the truth's ground velocity less the steady wind the flight was given (the truth file has
no airspeed column; turbulence is left in, as a pitot would see it).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from companion.actuators.airframe import load_airframe
from companion.control.flight.params import control_params
from companion.control.mission.executor import RELATIVE_FRAMES
from companion.control.mission.items import MissionItem
from companion.control.mission.plan import checked_plan
from companion.geodesy import LocalFrame
from mavlink_dialect import companion as d

G = 9.80665
OFF_LINE_M = 150.0  # farther than this from a leg, a sample belongs to another leg


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


def leg_margin_m(airframe: str) -> tuple[float, float]:
    """(margin at each end of a leg, cruise airspeed) from the airframe's defaults."""
    values = {p.name: p.default for p in control_params(load_airframe(airframe).control)}
    cruise = values["AIRSPEED_CRUISE"]
    radius = cruise**2 / (G * math.tan(math.radians(values["ROLL_LIMIT_DEG"]) * 0.8))
    l1 = values["NAVL1_DAMPING"] * values["NAVL1_PERIOD"] * cruise / math.pi
    return radius + l1, cruise


def score_track(
    truth: dict[str, list[float]],
    plan: Path | list[MissionItem],
    airframe: str,
    wind_ned: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> TrackScore:
    """Cross-track, height and airspeed errors on the straight parts of the legs."""
    items = checked_plan(plan)[0] if isinstance(plan, Path) else plan
    margin, cruise = leg_margin_m(airframe)
    lat, lon, alt = (np.asarray(truth[k], dtype=float) for k in ("lat", "lon", "alt"))
    if len(lat) == 0:
        return TrackScore(math.nan, math.nan, math.nan, math.nan, 0)
    frame = LocalFrame(lat[0], lon[0])
    north, east = np.array([frame.ne(a, b) for a, b in zip(lat, lon, strict=True)]).T
    wind = np.asarray(wind_ned, dtype=float)
    vel = np.column_stack([np.asarray(truth[k], dtype=float) for k in ("vn", "ve", "vd")])
    speed = np.linalg.norm(vel - wind, axis=1)
    xt: list[np.ndarray] = []
    dz: list[np.ndarray] = []
    dv: list[np.ndarray] = []
    for a, b in itertools.pairwise(items):
        if a.command != d.MAV_CMD_NAV_WAYPOINT or b.command != d.MAV_CMD_NAV_WAYPOINT:
            continue  # only waypoint-to-waypoint legs are straight lines
        pa, pb = frame.ne(a.x / 1e7, a.y / 1e7), frame.ne(b.x / 1e7, b.y / 1e7)
        length = math.hypot(pb[0] - pa[0], pb[1] - pa[1])
        if length <= 2 * margin:
            continue  # all turn, no straight part
        u = ((pb[0] - pa[0]) / length, (pb[1] - pa[1]) / length)
        along = (north - pa[0]) * u[0] + (east - pa[1]) * u[1]
        cross = -(north - pa[0]) * u[1] + (east - pa[1]) * u[0]
        on_leg = (along > margin) & (along < length - margin) & (np.abs(cross) < OFF_LINE_M)
        target = b.z + (alt[0] if b.frame in RELATIVE_FRAMES else 0.0)
        xt.append(np.abs(cross[on_leg]))
        dz.append(alt[on_leg] - target)
        dv.append(speed[on_leg] - cruise)
    return _summarise(xt, dz, dv)


def _summarise(xt: list[np.ndarray], dz: list[np.ndarray], dv: list[np.ndarray]) -> TrackScore:
    cross = np.concatenate(xt) if xt else np.array([])
    if len(cross) == 0:
        return TrackScore(math.nan, math.nan, math.nan, math.nan, 0)
    height, speed = np.concatenate(dz), np.concatenate(dv)
    return TrackScore(
        float(np.sqrt(np.mean(cross**2))),
        float(np.percentile(cross, 95)),
        float(np.sqrt(np.mean(height**2))),
        float(np.sqrt(np.mean(speed**2))),
        len(cross),
    )
