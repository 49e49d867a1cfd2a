"""Whether the aircraft stands on the ground, as the flight controller judges it."""

from __future__ import annotations

import math

from companion.messages import NavState

AIRBORNE_AGL_M = 10.0
LANDED_SPEED = 8.0  # m/s: slower than this near the ground is "on the ground"


def landed_now(
    landed: bool | None, agl: float, nav: NavState, airspeed: float, least: float
) -> bool:
    """On the ground after this solution (``landed`` None: the first; ``least``: the
    airframe's least airspeed, AIRSPEED_MIN)."""
    if landed is None:  # first solution: started on the runway or in the air?
        return agl < AIRBORNE_AGL_M and airspeed < least * 0.7
    if landed and agl > AIRBORNE_AGL_M and _moving(nav, airspeed):
        # Height alone is not flight: a drifting navigator can say 30 m while the
        # aircraft stands on the runway, and leaving "landed" opens the throttle.
        return False
    if not landed and agl < 2.0 and math.hypot(nav.vn_m_s, nav.ve_m_s) < LANDED_SPEED:
        return True
    return landed


def _moving(nav: NavState, airspeed: float) -> bool:
    ground = math.hypot(nav.vn_m_s, nav.ve_m_s)
    return max(ground, airspeed if math.isfinite(airspeed) else 0.0) >= LANDED_SPEED
