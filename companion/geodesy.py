"""A flat north/east frame around a reference point, for guidance over a few kilometres.

Imports nothing from the project: the mission executor and the control laws share it.

An equirectangular projection on the WGS-84 radii at the reference latitude: over 5 km
its error is below 0.1 m, far under GPS noise, and it costs a few multiplications.
"""

from __future__ import annotations

import math

A = 6378137.0  # WGS-84 semi-major axis, m
STANDARD_GRAVITY = 9.80665  # m/s², the conventional g the control laws use
E2 = 6.69437999014e-3  # first eccentricity squared


class LocalFrame:
    """North/east metres from (lat0, lon0) and back."""

    def __init__(self, lat0_deg: float, lon0_deg: float) -> None:
        self.lat0, self.lon0 = lat0_deg, lon0_deg
        s = math.sin(math.radians(lat0_deg))
        w = math.sqrt(1.0 - E2 * s * s)
        self.m_per_deg_n = math.radians(1.0) * A * (1.0 - E2) / w**3
        self.m_per_deg_e = math.radians(1.0) * A / w * math.cos(math.radians(lat0_deg))

    def ne(self, lat_deg: float, lon_deg: float) -> tuple[float, float]:
        """North and east of the reference, metres."""
        return (
            (lat_deg - self.lat0) * self.m_per_deg_n,
            (lon_deg - self.lon0) * self.m_per_deg_e,
        )

    def latlon(self, north: float, east: float) -> tuple[float, float]:
        """Latitude and longitude of a point given in metres north and east."""
        return self.lat0 + north / self.m_per_deg_n, self.lon0 + east / self.m_per_deg_e


def wrap_pi(angle: float) -> float:
    """An angle in [-π, π)."""
    return (angle + math.pi) % math.tau - math.pi
