"""A local north-east-down frame on the WGS-84 ellipsoid, through pyproj.

Exact (to the ellipsoid, not a sphere) at any distance: points go to Earth-centred
coordinates with pyproj and are rotated into the tangent plane at the reference. The
navigators work in metres in this frame; only their inputs and outputs are geodetic.
"""

from __future__ import annotations

import math

import numpy as np
import pyproj

_TO_ECEF = pyproj.Transformer.from_crs("EPSG:4979", "EPSG:4978")
_FROM_ECEF = pyproj.Transformer.from_crs("EPSG:4978", "EPSG:4979")


def normal_gravity(lat_deg: float, alt_m: float) -> float:
    """WGS-84 normal gravity (Somigliana) with the free-air correction, m/s²."""
    s2 = math.sin(math.radians(lat_deg)) ** 2
    g0 = 9.7803253359 * (1 + 0.00193185265241 * s2) / math.sqrt(1 - 0.00669437999013 * s2)
    return g0 - 3.086e-6 * alt_m


class LocalFrame:
    """NED metres about a reference point (latitude, longitude, height)."""

    def __init__(self, lat_deg: float, lon_deg: float, alt_m: float) -> None:
        self.ref = (lat_deg, lon_deg, alt_m)
        self.origin = np.array(_TO_ECEF.transform(lat_deg, lon_deg, alt_m))
        lat, lon = math.radians(lat_deg), math.radians(lon_deg)
        sl, cl, so, co = math.sin(lat), math.cos(lat), math.sin(lon), math.cos(lon)
        self.ecef_to_ned = np.array(
            [[-sl * co, -sl * so, cl], [-so, co, 0.0], [-cl * co, -cl * so, -sl]]
        )

    def ned(self, lat_deg: float, lon_deg: float, alt_m: float) -> np.ndarray:
        """A geodetic point in this frame."""
        ecef = np.array(_TO_ECEF.transform(lat_deg, lon_deg, alt_m))
        return self.ecef_to_ned @ (ecef - self.origin)

    def drop(self, north: float, east: float) -> float:
        """How far the reference height lies below the frame's plane at this horizontal
        position, m (down): the Earth curving away, 0 at the origin, 2.8 m 6 km out. A
        height measured from the ground (a barometer) is in the frame ``-(h - ref) + drop``."""
        lat, lon, _ = self.geodetic(np.array((north, east, 0.0)))
        return float(self.ned(lat, lon, self.ref[2])[2])

    def geodetic(self, ned: np.ndarray) -> tuple[float, float, float]:
        """A point of this frame as (latitude, longitude, height)."""
        x, y, z = self.origin + self.ecef_to_ned.T @ ned
        lat, lon, alt = _FROM_ECEF.transform(x, y, z)
        return float(lat), float(lon), float(alt)
