"""A point-mass aircraft for closed-loop tests of the guidance laws, without JSBSim.

Constant airspeed, coordinated turns (heading rate ``g·tan φ / V``, reached with a lag),
a first-order roll response towards the demanded bank with a rate limit, and a steady
wind: what lateral guidance sees of an aeroplane, at thousands of steps a second.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from companion.control.laws.fillet import corner_arc
from companion.control.laws.l1_guidance import L1Guidance, bank_for
from companion.geodesy import STANDARD_GRAVITY as G


@dataclass
class PointMass:
    """North/east position (m), heading and bank (rad); airspeed and wind in m/s."""

    airspeed: float = 36.0
    roll_tau_s: float = 0.35
    roll_rate_max: float = math.radians(60.0)
    # The heading rate follows the bank with a lag (sideslip, yaw damping): a JSBSim
    # Cessna keeps turning for a moment after its wings are level.
    turn_lag_s: float = 0.4
    bank_limit: float = math.radians(35.0)
    wind_ne: tuple[float, float] = (0.0, 0.0)
    north: float = 0.0
    east: float = 0.0
    heading: float = 0.0
    bank: float = 0.0
    turn_rate: float = 0.0
    track: list[tuple[float, float]] = field(default_factory=list)

    @property
    def velocity(self) -> tuple[float, float]:
        """Ground velocity, m/s north and east."""
        return (
            self.airspeed * math.cos(self.heading) + self.wind_ne[0],
            self.airspeed * math.sin(self.heading) + self.wind_ne[1],
        )

    def step(self, bank_dem: float, dt: float) -> None:
        """Fly ``dt`` seconds towards the demanded bank."""
        rate = (bank_dem - self.bank) / self.roll_tau_s
        rate = max(-self.roll_rate_max, min(self.roll_rate_max, rate))
        self.bank += rate * dt
        target = G * math.tan(self.bank) / self.airspeed
        self.turn_rate += (target - self.turn_rate) * min(1.0, dt / self.turn_lag_s)
        self.heading += self.turn_rate * dt
        vn, ve = self.velocity
        self.north += vn * dt
        self.east += ve * dt
        self.track.append((self.north, self.east))


def fly_legs(
    guidance: L1Guidance,
    aircraft: PointMass,
    points: list[tuple[float, float]],
    turn_radius: float,
    dt: float = 0.02,
    arcs: bool = True,
) -> list[list[tuple[float, float]]]:
    """Fly the legs between ``points`` (switching at the turn lead as the executor does);
    the positions flown while each leg was the current one. ``arcs=False``: guidance is
    not told where the leg before came from (L1 alone turns the corners)."""
    legs: list[list[tuple[float, float]]] = [[] for _ in points[1:]]
    for k in range(1, len(points)):
        a, b = points[k - 1], points[k]
        prev = points[k - 2] if k >= 2 and arcs else None
        lead = _lead(a, b, points[k + 1] if k + 1 < len(points) else None, turn_radius)
        for _ in range(int(4 * math.dist(a, b) / aircraft.airspeed / dt)):
            pos = (aircraft.north, aircraft.east)
            if math.dist(pos, b) <= max(lead, 1.0):
                break
            demand = guidance.line(pos, aircraft.velocity, a, b, dt, prev, turn_radius)
            aircraft.step(bank_for(demand.lat_acc, aircraft.bank_limit), dt)
            legs[k - 1].append((aircraft.north, aircraft.east))
    return legs


def _lead(a, b, nxt, radius: float) -> float:  # type: ignore[no-untyped-def]
    """Where the executor switches legs: the arc's own lead (one geometry for both)."""
    if nxt is None:
        return 0.0
    turn = math.remainder(
        math.atan2(nxt[1] - b[1], nxt[0] - b[0]) - math.atan2(b[1] - a[1], b[0] - a[0]),
        math.tau,
    )
    return corner_arc(turn, radius, math.dist(a, b), math.dist(b, nxt))[0]


def cross_track(
    track: list[tuple[float, float]], a: tuple[float, float], b: tuple[float, float]
) -> list[tuple[float, float]]:
    """(distance along a→b, signed cross-track error) of each position."""
    length = math.dist(a, b)
    u = ((b[0] - a[0]) / length, (b[1] - a[1]) / length)
    return [
        ((n - a[0]) * u[0] + (e - a[1]) * u[1], -(n - a[0]) * u[1] + (e - a[1]) * u[0])
        for n, e in track
    ]
