"""The GPS + compass navigator on a known flight: real time between fixes, outages, compass."""

from __future__ import annotations

import math

import numpy as np
import pytest

from companion.messages import Compass, GpsFix, NavFlags
from companion.navigation.gps_compass import EARTH_RADIUS_M, GpsCompassNavigator

LAT0, LON0, ALT0 = -37.9105, 145.1340, 100.0
VN, VE, VD = 18.0, 12.0, -1.0  # a steady climbing leg


def truth(t: float) -> tuple[float, float, float]:
    north, east = VN * t, VE * t
    lat = LAT0 + math.degrees(north / EARTH_RADIUS_M)
    lon = LON0 + math.degrees(east / (EARTH_RADIUS_M * math.cos(math.radians(LAT0))))
    return lat, lon, ALT0 - VD * t


def fix(t: float, rng: np.random.Generator, noise_m: float = 2.0) -> GpsFix:
    lat, lon, alt = truth(t)
    dn, de = rng.normal(0, noise_m, 2)
    msg = GpsFix(t_us=round(t * 1e6), fix_type=3, alt_msl_m=alt + rng.normal(0, 3))
    msg.lat_deg = lat + math.degrees(dn / EARTH_RADIUS_M)
    msg.lon_deg = lon + math.degrees(de / (EARTH_RADIUS_M * math.cos(math.radians(LAT0))))
    msg.vn_m_s, msg.ve_m_s = VN + rng.normal(0, 0.2), VE + rng.normal(0, 0.2)
    msg.vd_m_s, msg.eph_m = math.nan, noise_m
    return msg


def horizontal_error_m(state, t: float) -> float:
    lat, lon, _ = truth(t)
    dn = math.radians(state.lat_deg - lat) * EARTH_RADIUS_M
    de = math.radians(state.lon_deg - lon) * EARTH_RADIUS_M * math.cos(math.radians(LAT0))
    return math.hypot(dn, de)


def test_irregular_fixes_track_position_and_velocity():
    rng = np.random.default_rng(7)
    nav = GpsCompassNavigator()
    t, errors = 0.0, []
    while t < 120:
        nav.on_gps(fix(t, rng))
        state = nav.state(round(t * 1e6))
        errors.append(horizontal_error_m(state, t))
        t += rng.uniform(0.15, 1.6)  # 1-7 Hz, jittery, never the assumed 1 s
    assert np.sqrt(np.mean(np.square(errors[10:]))) < 2.0
    assert state.vn_m_s == pytest.approx(VN, abs=0.3) and state.ve_m_s == pytest.approx(VE, abs=0.3)
    assert state.flags & NavFlags.POSITION_VALID and not state.flags & NavFlags.DEAD_RECKONING


def test_outage_coasts_on_velocity_with_growing_uncertainty_and_recovers():
    rng = np.random.default_rng(3)
    nav = GpsCompassNavigator()
    for k in range(60):
        nav.on_gps(fix(k * 0.5, rng))
    before = nav.state(round(29.5e6))
    during = nav.state(round(59.5e6))  # 30 s without a fix
    assert during.flags & NavFlags.DEAD_RECKONING
    assert during.pos_std_m[0] > 5 * before.pos_std_m[0]
    assert horizontal_error_m(during, 59.5) < 30.0, "coasting on the last velocity"
    nav.on_gps(fix(60.0, rng))
    after = nav.state(round(60.0e6))
    assert not after.flags & NavFlags.DEAD_RECKONING
    assert horizontal_error_m(after, 60.0) < 5.0


def test_a_late_query_does_not_move_the_filter_and_lagging_fixes_still_count():
    rng = np.random.default_rng(5)
    nav = GpsCompassNavigator()
    for k in range(20):
        nav.on_gps(fix(k * 0.2, rng))
        nav.state(round((k * 0.2 + 0.15) * 1e6))  # compass-rate queries ahead of the fixes
    assert nav.t_kf_us == round(3.8e6)


def test_attitude_comes_from_the_compass_and_goes_stale():
    nav = GpsCompassNavigator()
    nav.on_compass(
        Compass(
            t_us=1_000_000,
            heading_rad=math.radians(350),
            pitch_rad=0.05,
            roll_rad=-0.2,
            temp_c=20.0,
        )
    )
    state = nav.state(1_100_000)
    assert state.yaw_rad == pytest.approx(math.radians(-10))
    assert (state.roll_rad, state.pitch_rad) == (-0.2, 0.05)
    w, x, y, z = state.q
    assert math.isclose(w * w + x * x + y * y + z * z, 1.0)
    assert state.flags & NavFlags.ATTITUDE_VALID and not state.flags & NavFlags.POSITION_VALID
    assert not nav.state(3_000_000).flags & NavFlags.ATTITUDE_VALID


def test_no_fix_and_garbage_fixes_are_rejected_and_counted():
    nav = GpsCompassNavigator()
    nav.on_gps(GpsFix(t_us=1, fix_type=1, lat_deg=LAT0, lon_deg=LON0))
    nav.on_gps(GpsFix(t_us=2, fix_type=3, lat_deg=math.nan, lon_deg=LON0))
    assert nav.rejected == 2 and nav.ref is None
