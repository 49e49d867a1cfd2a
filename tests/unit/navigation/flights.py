"""The synthetic flights the navigator tests fly (cached: each is generated once)."""

from __future__ import annotations

import functools
import math

from companion.messages import Baro, NavState
from companion.navigation.offline import Navigator
from companion.navigation.scoring import Errors
from ground.simulation import evaluation
from ground.simulation.synthetic_flight import FlightSpec, Leg
from ground.simulation.synthetic_log import SyntheticFlight, synthesize

DECLINATION = 11.7  # the synthetic field's (Melbourne)
SHORT = (  # 3 minutes: a straight, turns both ways, a climb, a speed change, an outage turn
    Leg(30), Leg(20, turn_deg_s=8), Leg(20, climb_m_s=2.0), Leg(20, turn_deg_s=-6),
    Leg(25, speed_m_s=30), Leg(30, turn_deg_s=7, speed_m_s=30), Leg(35),
)  # fmt: skip
OUTAGE = (120.0, 30.0)


@functools.cache
def flight(seed: int = 5, imu_hz: float = 100.0, latency: float = 0.0) -> SyntheticFlight:
    spec = FlightSpec(legs=SHORT, outage=OUTAGE, seed=seed, imu_hz=imu_hz, gps_latency_s=latency)
    return synthesize(spec)


def fly(
    navigator: str | Navigator, flight_: SyntheticFlight, drop: set[str] = frozenset()
) -> tuple[Errors, list[NavState]]:
    """Fly and score with the test flights' declination and outage."""
    return evaluation.fly(navigator, flight_, DECLINATION, OUTAGE, drop)


def perfect_baro(flight_: SyntheticFlight) -> list[Baro]:
    """A barometer that reads the true height above the start, at 25 Hz."""
    h0 = flight_.truth[0].alt_msl_m
    return [
        Baro(t_us=round(s.t_s * 1e6), alt_rel_m=s.alt_msl_m - h0, pressure_pa=math.nan)
        for s in flight_.truth[::4]  # the truth is at 100 Hz
    ]
