"""What the commander and the flight controller accept from the bus before they use it.

Pure: a message in, whether it is usable out. The link validates what comes from a
ground station, but the bus also carries what a navigator, a replay or a buggy plug-in
publishes; one infinite heading reaches ``cos`` in the wind estimator, one NaN roll
becomes NaN surface commands. A solution that fails here is not flown from (the
controller keeps its last good output) and not taken as home (the commander ignores it),
and each is counted. NaN is refused where the laws read a number; in a target it means
"not given", as the commander publishes it.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from companion.control.mission.items import MAX_ALT_M
from companion.messages import FlightMode, NavState, VehicleStatus

if TYPE_CHECKING:
    from companion.control.flight.attitude_modes import Sticks

# Beyond these a value is a broken input, not a state the aircraft can be in: an IMU
# saturates near 35 rad/s (2000 °/s), and no airframe here flies at 500 m/s.
MAX_ANGLE_RAD = 2 * math.pi  # attitude angles are published in [-π, π]; some slack
MAX_RATE_RAD_S = 40.0
MAX_SPEED_M_S = 500.0
MAX_RADIUS_M = 10_000.0  # as the commander's limit on an orbit
KNOWN_MODES = frozenset(int(m) for m in FlightMode)
NAV_RATES = ("roll_rate_rad_s", "pitch_rate_rad_s", "yaw_rate_rad_s")


# ``abs(x) <= limit`` throughout: finite and no larger than ``limit`` either way (NaN and
# infinity fail), written out because the controller asks at every step.


def _rate_usable(value: float) -> bool:
    """A body rate within an IMU's range, or NaN: not measured (gps_compass has no gyro)."""
    return math.isnan(value) or abs(value) <= MAX_RATE_RAD_S


def rates_or_zero(nav: NavState) -> NavState:
    """``nav`` with unmeasured (NaN) body rates as zero: the loops fly without damping terms."""
    # Written out: asked at every step, where a generator over the names cost more.
    isnan = math.isnan
    if not (isnan(nav.roll_rate_rad_s) or isnan(nav.pitch_rate_rad_s) or isnan(nav.yaw_rate_rad_s)):
        return nav
    copy = NavState.from_buffer_copy(nav)
    for f in NAV_RATES:
        if math.isnan(getattr(copy, f)):
            setattr(copy, f, 0.0)
    return copy


def place_usable(lat_deg: float, lon_deg: float, alt_msl_m: float) -> bool:
    """A place on Earth at a sane height (every coordinate given)."""
    return abs(lat_deg) <= 90.0 and abs(lon_deg) <= 180.0 and abs(alt_msl_m) <= MAX_ALT_M


def position_usable(nav: NavState) -> bool:
    """The solution's position, which the commander takes as home and judges the fence by."""
    return place_usable(nav.lat_deg, nav.lon_deg, nav.alt_msl_m)


def nav_usable(nav: NavState) -> bool:
    """Every field the control laws read is finite and within what an aircraft can be."""
    # Written out (a chained comparison fails for NaN and infinity alike): the controller
    # asks at every step, and the generators over field names were a tenth of its step.
    a, v = MAX_ANGLE_RAD, MAX_SPEED_M_S
    return (
        position_usable(nav)
        and -a <= nav.roll_rad <= a
        and -a <= nav.pitch_rad <= a
        and -a <= nav.yaw_rad <= a
        and _rate_usable(nav.roll_rate_rad_s)
        and _rate_usable(nav.pitch_rate_rad_s)
        and _rate_usable(nav.yaw_rate_rad_s)
        and -v <= nav.vn_m_s <= v
        and -v <= nav.ve_m_s <= v
        and -v <= nav.vd_m_s <= v
    )


def _target_usable(status: VehicleStatus) -> bool:
    """NaN means "not given" (each coordinate alone); anything else must be a place."""
    lat, lon, alt = status.target_lat_deg, status.target_lon_deg, status.target_alt_msl_m
    radius = status.target_radius_m
    return (
        (math.isnan(lat) or abs(lat) <= 90.0)
        and (math.isnan(lon) or abs(lon) <= 180.0)
        and (math.isnan(alt) or abs(alt) <= MAX_ALT_M)
        and (math.isnan(radius) or abs(radius) <= MAX_RADIUS_M)
    )


def status_usable(status: VehicleStatus) -> bool:
    """A known mode, a home that is a place (when it is said to be valid), a target that
    is a place or not given."""
    if status.mode and status.mode not in KNOWN_MODES:
        return False
    home = (status.home_lat_deg, status.home_lon_deg, status.home_alt_msl_m)
    if status.home_valid and not place_usable(*home):
        return False
    return _target_usable(status)


def sticks_usable(sticks: Sticks | None) -> bool:
    """No sticks, or sticks within their travel (roll, pitch, yaw ±1, throttle 0..1)."""
    if sticks is None:
        return True
    return (
        abs(sticks.roll) <= 1.0
        and abs(sticks.pitch) <= 1.0
        and abs(sticks.yaw) <= 1.0
        and 0.0 <= sticks.throttle <= 1.0
    )
