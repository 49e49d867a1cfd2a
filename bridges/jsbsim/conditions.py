"""Where a simulated flight starts and how rough its air is: plain values, without JSBSim.

The ``companion sim`` process reads them to check its options and hands them to the
simulator bridge, the one process that loads JSBSim (``fdm.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

# MIL-F-8785C probabilities of exceedance (JSBSim's table rows) and 20 ft wind speeds.
TURBULENCE = {"none": (0, 0.0), "light": (2, 15.0), "moderate": (3, 30.0), "severe": (5, 45.0)}


@dataclass(frozen=True)
class Home:
    """Where the aircraft starts: WGS-84 degrees, ground height above MSL, runway heading."""

    lat_deg: float = -37.9105
    lon_deg: float = 145.1340
    ground_msl_m: float = 80.0
    heading_deg: float = 90.0
