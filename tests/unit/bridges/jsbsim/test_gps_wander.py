"""``companion sim --gps-wander M`` sets the simulated GPS's slowly wandering error alone: 0
leaves its white noise, which averages out, and the default wanders by metres.
``--gps-receiver rtk`` is an RTK receiver with a fixed solution: centimetres, and its
sentences say so to the vehicle's driver; ``rtk-mavlink`` is one fed corrections through
the vehicle, float (decimetres) for its first seconds of them, then fixed."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pynmea2
import pytest

from bridges.jsbsim.bridge import _devices
from bridges.jsbsim.options import BridgeOptions
from bridges.sensor_models.sensor_errors import EARTH_RADIUS_M
from bridges.sensor_models.true_state import TrueState
from companion.messages import GpsFixType
from companion.sensors.line_framer import LineFramer
from companion.sensors.nmea_gps import NmeaGpsDecoder

STILL = TrueState(
    t_s=0.0, lat_deg=-37.9, lon_deg=145.1, alt_msl_m=100.0, alt_agl_m=20.0, roll=0.0,
    pitch=0.0, yaw=0.0, vn=0.0, ve=0.0, vd=0.0, p=0.0, q=0.0, r=0.0,
    f_body=(0.0, 0.0, -9.80665), airspeed_m_s=0.0,
)  # fmt: skip
RATE_HZ = 5.0


def _error_ne_m(lat: float, lon: float) -> tuple[float, float]:
    """A standing receiver's fix's error north and east of the truth, in metres."""
    cos_lat = math.cos(math.radians(STILL.lat_deg))
    north = math.radians(lat - STILL.lat_deg) * EARTH_RADIUS_M
    return north, math.radians(lon - STILL.lon_deg) * EARTH_RADIUS_M * cos_lat


def _smoothed_error_m(opts: BridgeOptions, seconds: float = 300.0) -> np.ndarray:
    """The horizontal position error of a standing receiver, averaged over 30 s windows."""
    errors = _devices(opts).errors
    north, east = [], []
    for _ in range(round(seconds * RATE_HZ)):
        lat, lon, _alt, _vel = errors.gps(STILL, 1.0 / RATE_HZ)
        n, e = _error_ne_m(lat, lon)
        north.append(n)
        east.append(e)
    window = np.ones(round(30 * RATE_HZ)) / round(30 * RATE_HZ)
    return np.hypot(np.convolve(north, window, "valid"), np.convolve(east, window, "valid"))


def test_without_wander_only_white_noise_is_left_which_averages_out():
    assert _smoothed_error_m(BridgeOptions(gps_wander_m=0.0)).max() < 0.15


def test_the_default_receiver_wanders_by_metres_and_the_option_scales_it():
    default = _smoothed_error_m(BridgeOptions())
    assert default.max() > 1.0
    doubled = _smoothed_error_m(BridgeOptions(gps_wander_m=2.0))  # the same seed
    assert doubled.max() == pytest.approx(2.0 * default.max(), rel=0.1)


@pytest.mark.parametrize("metres", [-0.1, 101.0, math.nan])
def test_a_wander_outside_0_to_100_m_is_refused(metres):
    with pytest.raises(ValueError, match="GPS wander"):
        BridgeOptions(gps_wander_m=metres)


def test_an_rtk_receiver_stays_within_centimetres_and_its_fix_says_rtk_fixed():
    opts = BridgeOptions(gps="rtk")
    assert _smoothed_error_m(opts).max() < 0.05
    devices, decoder = _devices(opts), NmeaGpsDecoder()
    fixes = []
    for k in range(3):  # the driver learns the receiver's order in its first epochs
        text = devices._gps(dataclasses.replace(STILL, t_s=0.2 * k))
        fixes += [f for line in LineFramer().feed(text) if (f := decoder.decode(line, k))]
    assert fixes[-1].fix_type == GpsFixType.RTK_FIXED
    assert fixes[-1].eph_m == pytest.approx(0.012)  # what the navigator is told (floored)


def test_a_receiver_not_modelled_or_a_wander_given_to_an_rtk_one_is_refused():
    with pytest.raises(ValueError, match="gps must be one of standard, rtk, rtk-mavlink"):
        BridgeOptions(gps="ppk")
    with pytest.raises(ValueError, match="the GPS wander is the standard receiver's"):
        BridgeOptions(gps="rtk", gps_wander_m=1.0)


def test_an_rtk_receiver_fed_through_the_vehicle_floats_then_fixes_while_corrections_last():
    devices = _devices(BridgeOptions(gps="rtk-mavlink"))

    def fix(t_s: float) -> tuple[str, float]:
        """GGA's fix quality and the fix's horizontal error (m)."""
        text = devices._gps(dataclasses.replace(STILL, t_s=t_s)).decode()
        gga = pynmea2.parse(text.splitlines()[0])
        return str(gga.gps_qual), math.hypot(*_error_ne_m(gga.latitude, gga.longitude))

    assert fix(0.2)[0] == "1"
    devices.corrected_until_s = 10.0  # the bridge heard corrections at 0.2 s
    floating = [fix(0.4 + 0.2 * i) for i in range(40)]  # 8 s from the first fresh epoch
    assert {q for q, _ in floating} == {"5"}  # RTK float while its ambiguities resolve
    assert max(e for _, e in floating) < 1.0
    fixed = [fix(8.4 + 0.2 * i) for i in range(7)]
    assert {q for q, _ in fixed} == {"4"}
    assert max(e for _, e in fixed) < 0.1
    assert fix(10.0)[0] == "1"  # stale: the plain fix
    devices.corrected_until_s = 30.0  # corrections again: float first, as from a cold start
    assert fix(20.0)[0] == "5" and fix(28.2)[0] == "4"
