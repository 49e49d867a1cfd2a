"""Pressure to height: the ISA troposphere, as every barometric altimeter does it."""

from __future__ import annotations

import math

SEA_LEVEL_PA = 101325.0
_EXPONENT = 0.190263  # R·L / (g·M) of the standard atmosphere
_SCALE_M = 44330.8  # T0 / L


def pressure_altitude_m(pressure_pa: float) -> float:
    """Height above the 1013.25 hPa level in the standard atmosphere (NaN if no pressure)."""
    if not math.isfinite(pressure_pa) or pressure_pa <= 0.0:
        return math.nan
    return _SCALE_M * (1.0 - (pressure_pa / SEA_LEVEL_PA) ** _EXPONENT)
