"""The modes a pilot flies by attitude: Manual (sticks straight to the surfaces),
Stabilized (ArduPlane's FBWA: the roll stick commands a bank angle up to
``ROLL_LIMIT_DEG``, the pitch stick a pitch angle up to ``PTCH_LIM_MAX_DEG`` /
``PTCH_LIM_MIN_DEG``), Acro (the sticks command roll and pitch rates up to
``ACRO_ROLL_RATE`` / ``ACRO_PITCH_RATE``; released, the attitude reached is held, as
ArduPlane's ACRO with ACRO_LOCKING; the roll is unlimited, the pitch within
``ACRO_PITCH_LIM``) and Rattitude (PX4's: Stabilized while both sticks are within
``RATT_TH`` of their centre, Acro beyond). In each the rudder stick adds to the turn
coordinator and the throttle stick is the throttle between ``THR_MIN`` and ``THR_MAX``.
Altitude and Position, which hold height and track, are ``assisted.py``.

Pure: the sticks, the attitude and the time step in, surface commands out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from companion.control.laws.attitude import AttitudeController
from companion.control.laws.limits import clamp
from companion.geodesy import wrap_pi
from companion.messages import FlightMode, NavState, PilotInput

if TYPE_CHECKING:
    from companion.control.flight.flight_params import FlightConfig

# Sticks older than this (by the navigation's sensor time) are not flown: the aircraft
# holds its wings level until the pilot is back or the failsafe takes it home.
STICKS_STALE_US = 500_000
# Acro's held attitude never leads the aircraft's by more than this: a target the aircraft
# cannot follow (full stick on a slow roll) would otherwise wind on and overshoot.
ACRO_LEAD_RAD = math.radians(30.0)


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
        roll, pitch, yaw, throttle = p.roll, p.pitch, p.yaw, p.throttle
        finite = math.isfinite  # written out: a receiver's frame is looked at every step
        if not (finite(roll) and finite(pitch) and finite(yaw) and finite(throttle)):
            continue
        return Sticks(
            clamp(roll, -1, 1), clamp(pitch, -1, 1), clamp(yaw, -1, 1), clamp(throttle, 0, 1)
        )
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


class AcroHold:
    """Acro's attitude target: the sticks move it at their rates, released it stays."""

    def __init__(self) -> None:
        self.target: tuple[float, float] | None = None

    def reset(self) -> None:
        """Out of Acro: the next Acro starts from the attitude the aircraft has then."""
        self.target = None

    def step(
        self, sticks: Sticks, nav: NavState, dt: float, cfg: FlightConfig
    ) -> tuple[float, float]:
        """The roll and pitch (rad) to hold now."""
        roll, pitch = self.target or (nav.roll_rad, nav.pitch_rad)
        roll += sticks.roll * math.radians(cfg["ACRO_ROLL_RATE"]) * dt
        pitch += sticks.pitch * math.radians(cfg["ACRO_PITCH_RATE"]) * dt
        lead = wrap_pi(roll - nav.roll_rad)
        roll = wrap_pi(nav.roll_rad + clamp(lead, -ACRO_LEAD_RAD, ACRO_LEAD_RAD))
        pitch = clamp(pitch, nav.pitch_rad - ACRO_LEAD_RAD, nav.pitch_rad + ACRO_LEAD_RAD)
        limit = math.radians(cfg["ACRO_PITCH_LIM"])
        self.target = (roll, clamp(pitch, -limit, limit))
        return self.target


def stick_attitude(sticks: Sticks, cfg: FlightConfig) -> tuple[float, float]:
    """Stabilized: the bank and pitch angles (rad) the sticks ask for."""
    if sticks.pitch >= 0:
        pitch = sticks.pitch * math.radians(cfg["PTCH_LIM_MAX_DEG"])
    else:
        pitch = -sticks.pitch * math.radians(cfg["PTCH_LIM_MIN_DEG"])
    return sticks.roll * cfg.roll_limit, pitch


def _rates_asked(mode: FlightMode, sticks: Sticks, cfg: FlightConfig) -> bool:
    if mode == FlightMode.ACRO:
        return True
    if mode != FlightMode.RATTITUDE:
        return False
    return max(abs(sticks.roll), abs(sticks.pitch)) > cfg["RATT_TH"]


def fly_pilot(
    mode: FlightMode,
    sticks: Sticks,
    nav: NavState,
    airspeed: float,
    dt: float,
    attitude: AttitudeController,
    cfg: FlightConfig,
    acro: AcroHold,
) -> PilotDemand:
    """Manual, Stabilized, Acro or Rattitude flight from the sticks."""
    if mode == FlightMode.MANUAL:
        attitude.reset()  # the loops start afresh when the pilot hands back
        return PilotDemand(sticks.roll, sticks.pitch, sticks.yaw, sticks.throttle)
    if _rates_asked(mode, sticks, cfg):
        roll_dem, pitch_dem = acro.step(sticks, nav, dt, cfg)
    else:
        acro.reset()
        roll_dem, pitch_dem = stick_attitude(sticks, cfg)
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
