"""The simulated aircraft starts on its runway facing the wind, as a pilot takes off.

The default airfield has one east-west runway. A take-off with the wind behind it climbs
over far more ground: with a 5 m/s wind from the west the J3Cub was 700 m past the zigzag
plan's first waypoint when its climb ended, and met the next leg 1.1 km along it.
"""

from __future__ import annotations

import math

import pytest

from ground.sitl.bridge.fdm import Flight, Home
from ground.sitl.bridge.options import BridgeOptions


@pytest.mark.parametrize(
    ("wind_ned", "heading"),
    [
        ((0.0, 5.0, 0.0), 270.0),  # from the west: take off towards it
        ((0.0, -5.0, 0.0), 90.0),  # from the east
        ((5.0, 0.0, 0.0), 90.0),  # a crosswind: the runway's usual direction
        ((0.0, 0.0, 0.0), 90.0),
    ],
)
def test_the_runway_is_used_into_the_wind(wind_ned: tuple, heading: float):
    assert BridgeOptions(wind_ned=wind_ned).home.heading_deg == heading


def test_a_heading_given_is_kept_whatever_the_wind():
    opts = BridgeOptions(home=Home(heading_deg=45.0), wind_ned=(0.0, 5.0, 0.0))
    assert opts.home.heading_deg == 45.0
    again = BridgeOptions.from_json(opts.to_json())
    assert again.home == opts.home


def test_the_aircraft_stands_on_the_runway_facing_the_wind():
    opts = BridgeOptions(wind_ned=(0.0, 5.0, 0.0))
    flight = Flight("c172p", 100.0, opts.home)
    flight.set_wind(*opts.wind_ned)
    flight.step()
    assert math.degrees(flight.state().yaw) % 360.0 == pytest.approx(270.0, abs=1.0)
