"""The landing's height from the rangefinder: used when valid, fresh and near level; the
navigator's height otherwise (companion/control/flight/range_height.py, landing.py)."""

from __future__ import annotations

import math

import pytest

from companion.control.flight.flight_params import CONTROL_PARAMS
from companion.control.flight.landing import Landing
from companion.control.flight.landing_io import AircraftState
from companion.control.flight.range_height import range_height
from companion.messages import LandPhase, RangeReading

V = {p.name: p.default for p in CONTROL_PARAMS}
NAV_T = 50_000_000


def reading(distance_m: float, t_us: int = NAV_T - 20_000, valid: int = 1) -> RangeReading:
    return RangeReading(
        t_us=t_us,
        distance_m=distance_m,
        min_distance_m=0.1,
        max_distance_m=12.0,
        ground_clearance_m=0.1,
        signal_quality=80,
        valid=valid,
    )


def test_a_valid_fresh_reading_gives_the_height_under_the_wheels():
    assert V["RNGFND_LANDING"] == 1.0
    roll, pitch = math.radians(10), math.radians(5)
    h = range_height(reading(5.0), NAV_T, roll, pitch, 1.0)
    assert h == pytest.approx(5.0 * math.cos(roll) * math.cos(pitch) - 0.1)
    # Newer than the solution by a little is as good as older by a little.
    assert math.isfinite(range_height(reading(5.0, NAV_T + 400_000), NAV_T, 0.0, 0.0, 1.0))


@pytest.mark.parametrize(
    ("rng", "roll", "use", "why"),
    [
        (None, 0.0, 1.0, "no rangefinder"),
        (reading(5.0, valid=0), 0.0, 1.0, "out of range or weak signal"),
        (reading(5.0, t_us=NAV_T - 600_000), 0.0, 1.0, "stale by the sensor time stamps"),
        (reading(5.0, t_us=NAV_T + 600_000), 0.0, 1.0, "from another time base"),
        (reading(5.0), math.radians(25), 1.0, "banked beyond 20 degrees"),
        (reading(5.0), 0.0, 0.0, "RNGFND_LANDING 0"),
        (reading(-1.0), 0.0, 1.0, "the device's error value"),
    ],
)
def test_an_unusable_reading_gives_no_height(rng, roll, use, why):
    assert math.isnan(range_height(rng, NAV_T, roll, 0.0, use)), why


def _state(height_nav: float, agl: float) -> AircraftState:
    return AircraftState(
        (0.0, 250.0), (0.0, 28.0), 100.0 + height_nav, -1.0, 0.0, math.pi / 2, 0.0, agl
    )


def test_the_flare_begins_on_the_range_height_when_there_is_one():
    # The navigator says 6 m (its altitude drifted); the lidar sees 2 m: flare now.
    land = Landing((0.0, -500.0), 150.0, (0.0, 300.0), 100.0)
    assert land.step(_state(6.0, 2.0), V, 0.02).phase == LandPhase.FLARE


def test_without_a_usable_range_the_navigator_height_decides():
    land = Landing((0.0, -500.0), 150.0, (0.0, 300.0), 100.0)
    assert land.step(_state(6.0, math.nan), V, 0.02).phase == LandPhase.APPROACH
    stale = range_height(reading(2.0, t_us=NAV_T - 2_000_000), NAV_T, 0.0, 0.0, 1.0)
    assert land.step(_state(6.0, stale), V, 0.02).phase == LandPhase.APPROACH
    assert land.step(_state(2.5, math.nan), V, 0.02).phase == LandPhase.FLARE


def test_the_flare_sinks_by_the_range_height():
    # Same navigator height, different lidar heights: the lower aircraft is asked to sink
    # slower, so it pitches up more.
    pitches = []
    for agl in (2.5, 0.8):
        land = Landing((0.0, -500.0), 150.0, (0.0, 300.0), 100.0)
        land.step(_state(2.5, 2.5), V, 0.02)
        dem = land.step(_state(2.5, agl), V, 0.02)
        assert dem.phase == LandPhase.FLARE
        pitches.append(dem.pitch)
    assert pitches[1] > pitches[0]
