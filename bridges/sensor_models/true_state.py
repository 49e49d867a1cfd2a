"""What an aircraft is really doing, in SI units: the input of every sensor model."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class TrueState:
    """Position WGS-84, velocity NED, attitude ZYX Euler, body FRD rates and specific force."""

    t_s: float
    lat_deg: float
    lon_deg: float
    alt_msl_m: float
    alt_agl_m: float
    roll: float
    pitch: float
    yaw: float  # [-π, π] from true north
    vn: float
    ve: float
    vd: float
    p: float  # body rates, rad/s
    q: float
    r: float
    f_body: tuple[float, float, float]  # specific force, m/s², body FRD
    airspeed_m_s: float
