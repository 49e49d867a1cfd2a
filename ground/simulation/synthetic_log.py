"""The sensor log (and truth) of a synthetic flight, as rows of the design's CSV formats."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bridges.sensor_models.sensor_errors import SensorErrors
from bridges.sensor_models.true_state import TrueState
from companion.navigation.estimate_csv import EstimateWriter
from ground.simulation.synthetic_flight import FlightSpec, trajectory

HEADER = (
    "t,kind,ax,ay,az,gx,gy,gz,lat,lon,alt_m,vn,ve,vd,fix,hdop,mx,my,mz,baro_alt_m,"
    "heading_deg,pitch_deg,roll_deg"
)
_COLUMNS = HEADER.split(",")
HDOP = 0.9


@dataclass
class SyntheticFlight:
    """Sensor rows (sorted by time) and the truth at every IMU sample."""

    rows: list[dict[str, float | str]]
    truth: list[TrueState]

    def write(self, log_path: str | Path, truth_path: str | Path | None = None) -> None:
        """The sensor log CSV and, if asked, the truth in the estimate format."""
        with Path(log_path).open("w") as out:
            out.write(HEADER + "\n")
            for row in self.rows:
                out.write(",".join(_cell(row.get(c, "")) for c in _COLUMNS) + "\n")
        if truth_path is not None:
            writer = EstimateWriter(truth_path)
            for s in self.truth:
                writer.add(s.t_s, s.roll, s.pitch, s.yaw, s.lat_deg, s.lon_deg, s.alt_msl_m,
                           s.vn, s.ve, s.vd)  # fmt: skip
            writer.close()


def _cell(value: float | str) -> str:
    if isinstance(value, str):
        return value
    return f"{value:.9g}" if math.isfinite(value) else ""


def synthesize(spec: FlightSpec) -> SyntheticFlight:
    """Fly the spec and record what its sensors would have said."""
    errors = SensorErrors(spec.noise, spec.field_model, spec.seed)
    jitter = np.random.default_rng(spec.seed + 1)
    rows: list[dict[str, float | str]] = []
    truth: list[TrueState] = []
    next_gps = next_mag = next_compass = 0.0
    last_imu = last_gps = 0.0
    for s in trajectory(spec):
        truth.append(s)
        imu = errors.imu(s, s.t_s - last_imu, 95.0)
        last_imu = s.t_s
        rows.append(dict(t=s.t_s, kind="imu", **_xyz("a", imu.accel), **_xyz("g", imu.gyro)))
        if s.t_s >= next_mag:
            rows.append(dict(t=s.t_s, kind="mag", **_xyz("m", imu.mag)))
            next_mag += 1.0 / spec.mag_hz
        if s.t_s >= next_compass:
            heading, pitch, roll = errors.compass(s)
            rows.append(dict(t=s.t_s, kind="compass", heading_deg=heading, pitch_deg=pitch,
                             roll_deg=roll))  # fmt: skip
            next_compass += 1.0 / spec.compass_hz
        if s.t_s >= next_gps:
            if not _in_outage(spec, s.t_s):
                rows.append(_gps_row(errors, s, s.t_s - last_gps, spec.gps_latency_s))
            last_gps = s.t_s
            period = 1.0 / spec.gps_hz
            next_gps += period * (1.0 + spec.gps_jitter * jitter.uniform(-1.0, 1.0))
    rows.sort(key=lambda r: r["t"])  # lagging fixes land among later IMU rows
    return SyntheticFlight(rows, truth)


def _xyz(prefix: str, v: np.ndarray) -> dict[str, float]:
    return {f"{prefix}x": float(v[0]), f"{prefix}y": float(v[1]), f"{prefix}z": float(v[2])}


def _in_outage(spec: FlightSpec, t_s: float) -> bool:
    return spec.outage is not None and spec.outage[0] <= t_s < spec.outage[0] + spec.outage[1]


def _gps_row(errors: SensorErrors, s: TrueState, dt: float, latency: float) -> dict:
    lat, lon, alt, vel = errors.gps(s, dt)
    return dict(t=s.t_s + latency, kind="gps", lat=lat, lon=lon, alt_m=alt, vn=float(vel[0]),
                ve=float(vel[1]), vd=float(vel[2]), fix=3.0, hdop=HDOP)  # fmt: skip
