"""The wind estimator: airspeed and wind from GPS ground velocity and heading alone.

A simulated aircraft flies at a known true airspeed in a known wind with noisy ground
velocity at 50 Hz; circling makes the whole wind observable, a straight leg only its
cross-track part.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from companion.control.laws.wind import WindEstimator

DT = 0.02  # 50 Hz
NOISE = 0.3  # m/s, 1 σ per ground velocity axis
WIND_FROM_WEST = (0.0, 6.0)  # blowing towards the east


def fly(
    estimator: WindEstimator,
    seconds: float,
    heading: Callable[[float], float],
    airspeed: Callable[[float], float],
    wind: tuple[float, float],
    rng: np.random.Generator,
    t0: float = 0.0,
) -> None:
    """Feed ``seconds`` of ground velocity = Va·[cos ψ, sin ψ] + wind + noise."""
    for k in range(round(seconds / DT)):
        t = t0 + k * DT
        psi, va = heading(t), airspeed(t)
        noise = rng.normal(0.0, NOISE, 2)
        vel = (
            va * math.cos(psi) + wind[0] + float(noise[0]),
            va * math.sin(psi) + wind[1] + float(noise[1]),
        )
        estimator.update(vel, psi, DT)


def circling(start_deg: float, rate_deg_s: float = 6.0) -> Callable[[float], float]:
    return lambda t: math.radians(start_deg + rate_deg_s * t)


@pytest.mark.parametrize(
    ("seed", "start_deg", "rate_deg_s", "wind"),
    [
        (1, 0.0, 6.0, WIND_FROM_WEST),
        (2, 137.0, 6.0, WIND_FROM_WEST),
        (3, 250.0, -6.0, WIND_FROM_WEST),  # circling the other way
        (4, 30.0, 6.0, (-4.0, 3.0)),  # 5 m/s from the north-west
    ],
)
def test_two_circles_reveal_the_wind_and_the_airspeed(
    seed: int, start_deg: float, rate_deg_s: float, wind: tuple[float, float]
):
    rng = np.random.default_rng(seed)
    estimator = WindEstimator()
    circle_s = 360.0 / abs(rate_deg_s)
    fly(estimator, 2 * circle_s, circling(start_deg, rate_deg_s), lambda t: 30.0, wind, rng)
    wn, we = estimator.wind_ne
    assert wn == pytest.approx(wind[0], abs=0.5)
    assert we == pytest.approx(wind[1], abs=0.5)
    assert estimator.airspeed == pytest.approx(30.0, abs=0.5)
    # The filter knows it: its wind uncertainty has shrunk well below the prior.
    assert math.sqrt(estimator.p[1][1]) < 1.0 and math.sqrt(estimator.p[2][2]) < 1.0


def test_straight_flight_in_calm_air_gives_airspeed_equal_to_ground_speed():
    rng = np.random.default_rng(5)
    estimator = WindEstimator()
    heading = math.radians(40.0)
    fly(estimator, 60.0, lambda t: heading, lambda t: 27.0, (0.0, 0.0), rng)
    assert estimator.airspeed == pytest.approx(27.0, abs=0.3)
    wn, we = estimator.wind_ne
    assert math.hypot(wn, we) < 0.5


def test_first_fix_starts_the_airspeed_at_the_ground_speed_along_the_nose():
    estimator = WindEstimator()
    assert estimator.airspeed == 0.0 and not estimator.started
    estimator.update((0.0, 25.0), math.radians(90.0), 0.0)  # heading east at 25 m/s
    assert estimator.started
    assert estimator.airspeed == pytest.approx(25.0, abs=0.1)
    assert estimator.wind_ne == pytest.approx((0.0, 0.0), abs=0.1)


def test_straight_leg_sees_only_the_cross_track_wind():
    # Heading north in a wind from the west: the east (cross-track) wind shows at once; the
    # along-track wind cannot be told from airspeed, so the filter holds it (at its prior)
    # and says the wind is not yet observable.
    rng = np.random.default_rng(6)
    estimator = WindEstimator()
    fly(estimator, 60.0, lambda t: 0.0, lambda t: 30.0, WIND_FROM_WEST, rng)
    assert estimator.wind_ne[1] == pytest.approx(6.0, abs=0.3)
    assert math.sqrt(estimator.p[2][2]) < 0.2
    assert not estimator.observable and estimator.wind_ne[0] == pytest.approx(0.0, abs=0.05)
    # What it can see is right: ground speed along the nose = airspeed + along-track wind.
    assert estimator.airspeed + estimator.wind_ne[0] == pytest.approx(30.0, abs=0.3)


def test_airspeed_follows_a_step_while_the_wind_stays_put():
    rng = np.random.default_rng(8)
    estimator = WindEstimator()

    def airspeed(t: float) -> float:
        return 30.0 if t < 120.0 else 24.0

    heading = circling(0.0)
    fly(estimator, 120.0, heading, airspeed, WIND_FROM_WEST, rng)
    fly(estimator, 4.0, heading, airspeed, WIND_FROM_WEST, rng, t0=120.0)
    assert estimator.airspeed == pytest.approx(24.0, abs=0.6)
    wn, we = estimator.wind_ne
    assert wn == pytest.approx(0.0, abs=0.5)
    assert we == pytest.approx(6.0, abs=0.5)


def test_airspeed_is_never_negative():
    estimator = WindEstimator()
    estimator.update((-20.0, 0.0), 0.0, 0.02)  # flying tail first, as the numbers go
    assert estimator.airspeed == 0.0


def test_covariance_stays_symmetric_and_positive():
    rng = np.random.default_rng(9)
    estimator = WindEstimator()
    fly(estimator, 90.0, circling(10.0), lambda t: 30.0, WIND_FROM_WEST, rng)
    p = np.array(estimator.p)
    assert np.allclose(p, p.T)
    assert np.all(np.linalg.eigvalsh(p) > 0.0)


def test_a_take_off_roll_is_not_taken_for_a_tailwind():
    # Accelerating along the runway, then climbing straight out: the along-track wind is
    # unobservable, so the airspeed must follow the ground speed instead of the wind
    # soaking up the acceleration (which once made the estimate collapse to 5 m/s).
    estimator = WindEstimator()
    for i in range(1000):  # 20 s on the wheels, 0 → 25 m/s
        estimator.on_ground((0.0, 1.25 * i * 0.02), math.pi / 2)
    for i in range(1500):  # 30 s of straight climb-out, still speeding up to 30 m/s
        speed = 25.0 + 5.0 * min(1.0, i / 1000)
        estimator.update((0.0, speed), math.pi / 2, 0.02)
    assert estimator.airspeed == pytest.approx(30.0, abs=0.5)
    assert estimator.wind_ne[1] == pytest.approx(0.0, abs=0.1)
