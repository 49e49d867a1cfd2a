"""How far an estimate is from the truth: the figures ``benchmarks/nav_accuracy.py`` prints."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

EARTH_RADIUS_M = 6_378_137.0


@dataclass(frozen=True)
class Errors:
    """RMS and 95th percentile of each error, and the position error after an outage."""

    tilt_rms_deg: float  # roll and pitch together
    tilt_p95_deg: float
    yaw_rms_deg: float
    yaw_p95_deg: float
    pos_rms_m: float  # horizontal, while GPS was available
    pos_p95_m: float
    vel_rms_m_s: float
    vel_p95_m_s: float
    outage_end_m: float  # horizontal position error at the end of the GPS outage (nan: none)


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if len(x) else math.nan


def _p95(x: np.ndarray) -> float:
    return float(np.percentile(np.abs(x), 95)) if len(x) else math.nan


def score(
    est: dict[str, npt.NDArray[np.float64]],
    truth: dict[str, npt.NDArray[np.float64]],
    outage: tuple[float, float] | None = None,
    settle_s: float = 30.0,
) -> Errors:
    """Compare the estimate with the truth interpolated to its times, after ``settle_s``."""
    t = est["t"]
    keep: npt.NDArray[np.bool_] = (t >= truth["t"][0] + settle_s) & (t <= truth["t"][-1])
    keep &= np.isfinite(est["lat"]) & np.isfinite(est["roll"])
    t = t[keep]

    def true(col: str) -> npt.NDArray[np.float64]:
        return np.interp(t, truth["t"], np.unwrap(truth[col]) if col == "yaw" else truth[col])

    def err(col: str) -> npt.NDArray[np.float64]:
        return np.remainder(est[col][keep] - true(col) + math.pi, math.tau) - math.pi

    tilt = np.degrees(np.concatenate([err("roll"), err("pitch")]))
    yaw = np.degrees(err("yaw"))
    north = np.radians(est["lat"][keep] - true("lat")) * EARTH_RADIUS_M
    east = np.radians(est["lon"][keep] - true("lon")) * EARTH_RADIUS_M
    east *= np.cos(np.radians(true("lat")))
    horiz = np.hypot(north, east)
    vel = np.sqrt(sum((est[c][keep] - true(c)) ** 2 for c in ("vn", "ve", "vd")))
    with_gps = np.ones_like(t, dtype=bool)
    outage_end = math.nan
    if outage is not None:
        start, length = outage
        with_gps = (t < start) | (t > start + length + 10.0)
        end = np.searchsorted(t, start + length)
        if 0 < end <= len(t):
            outage_end = float(horiz[end - 1])
    return Errors(
        _rms(tilt), _p95(tilt), _rms(yaw), _p95(yaw), _rms(horiz[with_gps]),
        _p95(horiz[with_gps]), _rms(vel[with_gps]), _p95(vel[with_gps]), outage_end,
    )  # fmt: skip


def columns_of(states: list, fields: dict[str, str]) -> dict[str, np.ndarray]:
    """NavState list → estimate columns (``fields`` maps column → NavState attribute)."""
    return {col: np.array([getattr(s, attr) for s in states]) for col, attr in fields.items()}


NAV_FIELDS = {
    "roll": "roll_rad", "pitch": "pitch_rad", "yaw": "yaw_rad", "lat": "lat_deg",
    "lon": "lon_deg", "alt": "alt_msl_m", "vn": "vn_m_s", "ve": "ve_m_s", "vd": "vd_m_s",
}  # fmt: skip
