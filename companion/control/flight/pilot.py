"""The modes a pilot flies: Manual (sticks straight to the surfaces) and Stabilized
(ArduPlane's FBWA: the roll stick commands a bank angle up to ``ROLL_LIMIT_DEG``, the
pitch stick a pitch angle up to ``PTCH_LIM_MAX_DEG`` / ``PTCH_LIM_MIN_DEG``, the rudder
stick adds to the turn coordinator, and the throttle stick is the throttle between
``THR_MIN`` and ``THR_MAX``).

Pure: the sticks, the attitude and the time step in, surface commands out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from companion.control.flight.params import FlightConfig
from companion.control.laws.attitude import AttitudeController
from companion.control.laws.limits import clamp
from companion.messages import FlightMode, NavState, PilotInput

# Sticks older than this (by the navigation's sensor time) are not flown: the aircraft
# holds its wings level until the pilot is back or the failsafe takes it home.
STICKS_STALE_US = 500_000
PILOT_MODES = frozenset({FlightMode.MANUAL, FlightMode.STABILIZED})


@dataclass(frozen=True)
class Sticks:
    """Roll, pitch, yaw in [-1, 1] (right, nose up, right), throttle in [0, 1]."""

    roll: float
    pitch: float
    yaw: float
    throttle: float

    @classmethod
    def neutral(cls) -> Sticks:
        """Hands off: wings level, level pitch, no throttle."""
        return cls(0.0, 0.0, 0.0, 0.0)


def pilot_sticks(now_us: int, *inputs: PilotInput | None) -> Sticks | None:
    """The first of ``inputs`` (the receiver first: the safety pilot has the last word)
    that is a pilot's and fresh at sensor time ``now_us``; None when none is."""
    for p in inputs:
        if p is None or not p.usable() or now_us - p.t_us > STICKS_STALE_US:
            continue
        values = (p.roll, p.pitch, p.yaw, p.throttle)
        if not all(math.isfinite(v) for v in values):
            continue
        return Sticks(
            clamp(p.roll, -1, 1), clamp(p.pitch, -1, 1), clamp(p.yaw, -1, 1),
            clamp(p.throttle, 0, 1),
        )  # fmt: skip
    return None


@dataclass(frozen=True)
class PilotDemand:
    """Surfaces and the attitude asked for (NaN in Manual)."""

    aileron: float
    elevator: float
    rudder: float
    throttle: float
    roll: float = math.nan
    pitch: float = math.nan


def fly_pilot(
    mode: FlightMode,
    sticks: Sticks,
    nav: NavState,
    airspeed: float,
    dt: float,
    attitude: AttitudeController,
    cfg: FlightConfig,
) -> PilotDemand:
    """Manual or Stabilized flight from the sticks."""
    if mode == FlightMode.MANUAL:
        attitude.reset()  # the loops start afresh when the pilot hands back
        return PilotDemand(sticks.roll, sticks.pitch, sticks.yaw, sticks.throttle)
    roll_dem = sticks.roll * cfg.roll_limit
    if sticks.pitch >= 0:
        pitch_dem = sticks.pitch * math.radians(cfg["PTCH_LIM_MAX_DEG"])
    else:
        pitch_dem = -sticks.pitch * math.radians(cfg["PTCH_LIM_MIN_DEG"])
    s = attitude.step(
        roll_dem,
        pitch_dem,
        (nav.roll_rad, nav.pitch_rad),
        (nav.roll_rate_rad_s, nav.pitch_rate_rad_s, nav.yaw_rate_rad_s),
        airspeed if math.isfinite(airspeed) else cfg["AIRSPEED_CRUISE"],
        dt,
    )
    throttle = cfg["THR_MIN"] + sticks.throttle * (cfg["THR_MAX"] - cfg["THR_MIN"])
    rudder = clamp(s.rudder + sticks.yaw, -1.0, 1.0)
    return PilotDemand(s.aileron, s.elevator, rudder, throttle, roll_dem, pitch_dem)
