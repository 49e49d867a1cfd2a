"""A local north-east-down frame on the WGS-84 ellipsoid.

Exact (to the ellipsoid, not a sphere) at any distance: points go to Earth-centred
coordinates and are rotated into the tangent plane at the reference. The navigators work in
metres in this frame; only their inputs and outputs are geodetic.

The two conversions are written here rather than taken from pyproj: they are a few lines
of textbook geodesy, and pyproj (PROJ, its database and SQLite) cost the vehicle ~15 MB of
memory for them. tests/unit/navigation/test_local_frame.py holds them to pyproj.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from companion.geodesy import E2, A

_LAT_TOLERANCE_RAD = 1e-15
_MAX_ITERATIONS = 10
_B_OVER_A = math.sqrt(1 - E2)  # the ellipsoid's semi-minor axis over its semi-major
_B = A * _B_OVER_A
_EP2 = E2 / (1 - E2)  # the second eccentricity, squared


def _prime_vertical_radius(sin_lat: float) -> float:
    """N: the ellipsoid's radius of curvature square to the meridian, m."""
    return A / math.sqrt(1 - E2 * sin_lat * sin_lat)


def ecef(lat_deg: float, lon_deg: float, alt_m: float) -> tuple[float, float, float]:
    """Earth-centred, Earth-fixed coordinates (m) of a point above the ellipsoid."""
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    sin_lat, cos_lat = math.sin(lat), math.cos(lat)
    n = _prime_vertical_radius(sin_lat)
    r = (n + alt_m) * cos_lat
    return r * math.cos(lon), r * math.sin(lon), (n * (1 - E2) + alt_m) * sin_lat


def geodetic(x: float, y: float, z: float) -> tuple[float, float, float]:
    """Latitude, longitude (deg) and height above the ellipsoid (m) of an ECEF point.

    The latitude solves tan(lat) = (z + e² N(lat) sin(lat)) / p by fixed-point iteration,
    each step shrinking the error by about e² (1/150). It starts from Bowring's
    closed-form estimate, already within ~1e-10 rad near the Earth's surface, so one or two
    steps reach 1e-15 rad (from the spherical answer it took five to seven).
    """
    p = math.hypot(x, y)
    beta = math.atan2(z, p * _B_OVER_A)  # the parametric latitude, nearly
    sin_b, cos_b = math.sin(beta), math.cos(beta)
    lat = math.atan2(z + _EP2 * _B * sin_b**3, p - E2 * A * cos_b**3)
    for _ in range(_MAX_ITERATIONS):
        sin_lat = math.sin(lat)
        new = math.atan2(z + E2 * _prime_vertical_radius(sin_lat) * sin_lat, p)
        done = abs(new - lat) < _LAT_TOLERANCE_RAD
        lat = new
        if done:
            break
    sin_lat, cos_lat = math.sin(lat), math.cos(lat)
    # Projected on the normal: well conditioned at every latitude, poles included.
    alt = p * cos_lat + z * sin_lat - A * A / _prime_vertical_radius(sin_lat)
    return math.degrees(lat), math.degrees(math.atan2(y, x)), alt


def normal_gravity(lat_deg: float, alt_m: float) -> float:
    """WGS-84 normal gravity (Somigliana) with the free-air correction, m/s²."""
    s2 = math.sin(math.radians(lat_deg)) ** 2
    g0 = 9.7803253359 * (1 + 0.00193185265241 * s2) / math.sqrt(1 - 0.00669437999013 * s2)
    return g0 - 3.086e-6 * alt_m


class LocalFrame:
    """NED metres about a reference point (latitude, longitude, height)."""

    def __init__(self, lat_deg: float, lon_deg: float, alt_m: float) -> None:
        self.ref = (lat_deg, lon_deg, alt_m)
        self.origin: npt.NDArray[np.float64] = np.array(ecef(lat_deg, lon_deg, alt_m))
        lat, lon = math.radians(lat_deg), math.radians(lon_deg)
        sl, cl, so, co = math.sin(lat), math.cos(lat), math.sin(lon), math.cos(lon)
        self.ecef_to_ned: npt.NDArray[np.float64] = np.array(
            [[-sl * co, -sl * so, cl], [-so, co, 0.0], [-cl * co, -cl * so, -sl]]
        )
        self._origin = tuple(self.origin.tolist())
        self._ned_to_ecef = tuple(tuple(row) for row in self.ecef_to_ned.T.tolist())

    def ned(self, lat_deg: float, lon_deg: float, alt_m: float) -> np.ndarray:
        """A geodetic point in this frame."""
        point = np.array(ecef(lat_deg, lon_deg, alt_m))
        return self.ecef_to_ned @ (point - self.origin)

    def drop(self, north: float, east: float) -> float:
        """How far the reference height lies below the frame's plane at this horizontal
        position, m (down): the Earth curving away, 0 at the origin, 2.8 m 6 km out. A
        height measured from the ground (a barometer) is in the frame ``-(h - ref) + drop``."""
        lat, lon, _ = self.geodetic((north, east, 0.0))
        return float(self.ned(lat, lon, self.ref[2])[2])

    def geodetic(self, ned: Sequence[float]) -> tuple[float, float, float]:
        """A point of this frame as (latitude, longitude, height)."""
        # In floats: the navigator asks at every publication, and numpy's per-call cost
        # for one 3-vector was most of the conversion.
        n, e, d = ned  # then as floats, written out (a generator cost more than the sums)
        n, e, d = float(n), float(e), float(d)
        (x0, y0, z0), (cx, cy, cz) = self._origin, self._ned_to_ecef
        x = x0 + cx[0] * n + cx[1] * e + cx[2] * d
        y = y0 + cy[0] * n + cy[1] * e + cy[2] * d
        z = z0 + cz[0] * n + cz[1] * e + cz[2] * d
        return geodetic(x, y, z)
