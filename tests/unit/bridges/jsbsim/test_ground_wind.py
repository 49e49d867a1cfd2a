"""A slow aircraft on its wheels feels only the wind its flight model can take: JSBSim's
aerodynamics, fitted to flight, press a J3Cub onto the runway in a tailwind and stand it on
its nose with the wind abeam. The simulator keeps the airflow coming from ahead there, and
gives the whole wind to a fast or flying aircraft."""

from __future__ import annotations

import math

import pytest

from bridges.jsbsim.fdm import Flight, Home
from bridges.jsbsim.ground_wind import wind_share
from bridges.sensor_models.sensor_errors import body_from_ned

RATE_HZ = 100.0
EAST = math.pi / 2
CUB_PITCH = math.radians(12.0)  # resting on its tail wheel


def _share(ground_east_m_s: float, wind_ned: tuple[float, float, float]) -> float:
    """The share an aircraft facing east at the Cub's resting pitch feels."""
    rotation = body_from_ned(0.0, CUB_PITCH, EAST)
    return wind_share(rotation @ (0.0, ground_east_m_s, 0.0), rotation @ wind_ned)


def test_body_axes_of_an_aircraft_facing_east():
    x, y, z = body_from_ned(0.0, 0.0, EAST) @ (0.0, 5.0, 0.0)
    assert (x, y, z) == pytest.approx((5.0, 0.0, 0.0))
    x, y, z = body_from_ned(0.0, 0.0, EAST) @ (5.0, 0.0, 0.0)  # north is its left
    assert (x, y, z) == pytest.approx((0.0, -5.0, 0.0))


def test_a_headwind_is_felt_whole_even_standing_still():
    assert _share(0.0, (0.0, -5.0, 0.0)) == 1.0


@pytest.mark.parametrize("wind", [(5.0, 0.0, 0.0), (-5.0, 0.0, 0.0), (0.0, 5.0, 0.0)])
def test_a_stopped_aircraft_feels_no_wind_from_the_side_or_behind(wind):
    assert _share(0.0, wind) == 0.0


def test_a_crosswind_grows_in_with_the_ground_speed():
    shares = [_share(gs, (5.0, 0.0, 0.0)) for gs in (1.0, 3.0, 6.0, 9.0, 20.0)]
    assert shares == sorted(shares)
    assert 0.0 < shares[0] < 0.5 and shares[-2:] == [1.0, 1.0]
    # The air felt meets it 30 degrees off the nose while the share is cut.
    for gs, k in zip((1.0, 3.0, 6.0), shares, strict=False):
        u, v, _w = body_from_ned(0.0, CUB_PITCH, EAST) @ (-5.0 * k, gs, 0.0)
        assert math.degrees(math.atan2(abs(v), u)) == pytest.approx(30.0)


def _cub(wind: tuple[float, float, float]) -> Flight:
    flight = Flight("J3Cub", RATE_HZ, Home())
    flight.set_wind(*wind)
    return flight


@pytest.mark.parametrize("wind", [(5.0, 0.0, 0.0), (-5.0, 0.0, 0.0)])
def test_a_parked_cub_with_the_wind_abeam_stays_on_its_wheels(wind):
    """Before: flipped on its back within 1.7 s."""
    flight = _cub(wind)
    for _ in range(round(10 * RATE_HZ)):
        flight.set_controls({"throttle": 0.0})
        flight.step()
        s = flight.state()
        assert abs(math.degrees(s.roll)) < 5.0 and 5.0 < math.degrees(s.pitch) < 15.0


def test_a_cub_takes_off_from_a_tail_and_crosswind():
    """Before: pinned to the runway at 3.6 m/s, the speed of the tailwind, at full throttle."""
    flight = _cub((-3.1, 3.9, 0.0))  # 3.9 m/s behind, 3.1 m/s from the left
    for _ in range(round(15 * RATE_HZ)):
        flight.set_controls({"throttle": 1.0, "elevator": 0.3})
        flight.step()
    s = flight.state()
    assert math.hypot(s.vn, s.ve) > 12.0
    assert flight.wind_share == 1.0  # fast enough for the whole wind


def test_in_the_air_the_whole_wind():
    flight = Flight("c172p", RATE_HZ, Home(), airborne_agl_m=300.0, speed_m_s=50.0)
    flight.set_wind(0.0, 10.0, 0.0)  # a tailwind
    flight.step()
    assert flight.wind_share == 1.0
    assert flight.fdm["atmosphere/wind-east-fps"] * 0.3048 == pytest.approx(10.0)
