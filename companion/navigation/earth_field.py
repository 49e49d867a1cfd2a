"""The Earth's magnetic field where the vehicle is, from the World Magnetic Model (pygeomag).

The navigator needs the declination to turn a magnetic heading into a true one, and the
field's inclination and strength to tell a clean magnetometer reading from a disturbed one
(motor currents, steel, a poor hard-iron calibration): a disturbance that bends the heading
also bends the inclination or changes the strength, which the model lets us see.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

# The field drifts by a fraction of a degree per year. Without a date (a replayed log)
# the middle of the years most logs come from is the best guess: ~1° off at worst.
DEFAULT_YEAR = 2020.0
NT_PER_GAUSS = 1e5
# Each model's coefficients hold for five years from its epoch.
_MODELS = ((2020.0, "wmm/WMM_2015v2.COF"), (2025.0, "wmm/WMM_2020.COF"), (math.inf, "wmm/WMM.COF"))


@dataclass(frozen=True)
class EarthField:
    """The main field at a place: angles in radians, strength in gauss."""

    declination: float
    inclination: float
    intensity_gauss: float

    def ned(self) -> np.ndarray:
        """The field vector, NED, gauss."""
        d, i, f = self.declination, self.inclination, self.intensity_gauss
        return f * np.array([math.cos(i) * math.cos(d), math.cos(i) * math.sin(d), math.sin(i)])

    @property
    def horizontal_gauss(self) -> float:
        """The horizontal intensity: what a heading is measured against."""
        return self.intensity_gauss * math.cos(self.inclination)


@functools.lru_cache(maxsize=3)
def _model(coefficients: str) -> Any:  # a pygeomag GeoMag: pygeomag has no types
    from pygeomag import GeoMag

    return GeoMag(coefficients_file=coefficients)


def wmm_field(
    lat_deg: float, lon_deg: float, alt_m: float = 0.0, year: float = DEFAULT_YEAR
) -> EarthField:
    """The World Magnetic Model's field at a place and time (decimal year)."""
    coefficients = next(name for until, name in _MODELS if year < until)
    result = _model(coefficients).calculate(
        glat=lat_deg, glon=lon_deg, alt=alt_m / 1000.0, time=year,
        allow_date_outside_lifespan=True,
    )  # fmt: skip
    return EarthField(math.radians(result.d), math.radians(result.i), result.f / NT_PER_GAUSS)


def configured_field(
    lat_deg: float, lon_deg: float, alt_m: float, year: float, declination_deg: float | None
) -> EarthField:
    """The World Magnetic Model's field, with the configured declination when one is set
    (None: the model's)."""
    field = wmm_field(lat_deg, lon_deg, alt_m, year)
    if declination_deg is None:
        return field
    return EarthField(math.radians(declination_deg), field.inclination, field.intensity_gauss)
