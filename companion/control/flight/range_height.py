"""Height above the runway from a downward rangefinder, when it can be trusted.

A lidar measures along its beam; over flat ground the height is the distance times
cos(roll)·cos(pitch), less what it reads standing on the wheels (RNGFND1_GNDCLR), so the
height is 0 at touchdown as the navigator's height above the landing point is. It is
used (``RNGFND_LANDING`` = 1, as ArduPlane's) only when the reading is valid (in the
device's range, signal strong enough), was measured within ``MAX_AGE_S`` of the
navigation solution (by the sensors' time stamps, never by when the processes ran), and
the wings are within ``MAX_BANK`` of level: banked further, the beam reaches the ground
far to the side, where the terrain is not the runway's. Otherwise the landing flies on
the navigator's height, as without a rangefinder. Pure: numbers in, a height or NaN out.
"""

from __future__ import annotations

import math

from companion.messages import RangeReading

MAX_AGE_S = 0.5
MAX_BANK = math.radians(20.0)
MAX_PITCH = math.radians(20.0)


def range_height(
    reading: RangeReading | None, nav_t_us: int, roll: float, pitch: float, use: float
) -> float:
    """Height above the ground under the aircraft (m), or NaN when the range is not usable."""
    if use < 0.5 or reading is None or not reading.valid:
        return math.nan
    if abs(reading.t_us - nav_t_us) > MAX_AGE_S * 1e6:
        return math.nan
    if not (abs(roll) <= MAX_BANK and abs(pitch) <= MAX_PITCH):
        return math.nan
    distance = reading.distance_m
    if not (math.isfinite(distance) and distance > 0.0):
        return math.nan
    return distance * math.cos(roll) * math.cos(pitch) - reading.ground_clearance_m
