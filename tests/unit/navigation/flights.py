"""The synthetic flights the navigator tests fly (cached: each is generated once)."""

from __future__ import annotations

import functools

from companion.messages import NavState
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
