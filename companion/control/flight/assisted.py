"""Altitude and Position: a pilot on the sticks with the height (and the track) held.

As PX4's fixed-wing modes of those names (ArduPlane's FBWB and CRUISE):
- the roll stick asks for a bank angle up to ``ROLL_LIMIT_DEG``; centred, the wings are
  levelled and, in Position, the track over the ground the aircraft then has is held
  against the wind (MAVLink's CRUISE standard mode);
- the pitch stick asks for a climb up to ``TECS_CLMB_MAX`` or a sink up to
  ``TECS_SINK_MAX``; centred, the height the aircraft has when it is released is held;
- the throttle stick asks for an airspeed: ``AIRSPEED_MIN`` at idle, ``AIRSPEED_CRUISE``
  at half, ``AIRSPEED_MAX`` at full; the energy controller finds the throttle;
- the rudder stick adds to the turn coordinator.

Pure: the sticks and the navigation solution in, a setpoint for the energy controller and
the line guidance (or the bank angle asked for) out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from companion.control.flight.attitude_modes import Sticks
from companion.control.flight.flight_params import FlightConfig
from companion.control.mission.executor import Kind, Setpoint
from companion.messages import FlightMode, NavState

STICK_DEADBAND = 0.05  # a stick this near its centre is centred
LEVEL_RAD = math.radians(5.0)  # the track is taken once the wings are this level
LINE_LENGTH_M = 1e5  # the held track runs on for ever


@dataclass(frozen=True)
class AssistedDemand:
    """What to fly: ``setpoint`` (height, speed and, roll NaN, the line), the bank angle
    asked for (NaN: follow the line) and how fast the height demand moves."""

    setpoint: Setpoint
    roll: float
    climb_ff: float


def track_ahead(pos: tuple[float, float], nav: NavState) -> tuple[float, float]:
    """A point far along the track over the ground the aircraft now has, from ``pos``."""
    course = math.atan2(nav.ve_m_s, nav.vn_m_s)
    return pos[0] + LINE_LENGTH_M * math.cos(course), pos[1] + LINE_LENGTH_M * math.sin(course)


def centred(stick: float) -> bool:
    """Whether a stick is within the dead band of its centre."""
    return abs(stick) <= STICK_DEADBAND


def stick_speed(throttle: float, cfg: FlightConfig) -> float:
    """The airspeed the throttle stick asks for (m/s)."""
    low, cruise, high = cfg["AIRSPEED_MIN"], cfg["AIRSPEED_CRUISE"], cfg["AIRSPEED_MAX"]
    if throttle <= 0.5:
        return low + (cruise - low) * throttle / 0.5
    return cruise + (high - cruise) * (throttle - 0.5) / 0.5


def stick_climb(pitch: float, cfg: FlightConfig) -> float:
    """The climb rate the pitch stick asks for (m/s, negative down; 0 when centred)."""
    if centred(pitch):
        return 0.0
    return pitch * (cfg["TECS_CLMB_MAX"] if pitch > 0 else cfg["TECS_SINK_MAX"])


class AssistedHold:
    """The height and the track held while the sticks are centred."""

    def __init__(self) -> None:
        self.alt: float | None = None
        self.line: tuple[tuple[float, float], tuple[float, float]] | None = None

    def reset(self) -> None:
        """On entering the mode: hold what the aircraft has then."""
        self.alt = self.line = None

    def step(
        self, mode: FlightMode, sticks: Sticks, pos: tuple[float, float], nav: NavState,
        cfg: FlightConfig,
    ) -> AssistedDemand:  # fmt: skip
        """What to fly for these sticks at this position (local north, east in m)."""
        climb = stick_climb(sticks.pitch, cfg)
        if climb or self.alt is None:
            self.alt = nav.alt_msl_m  # the height demand moves with the stick (climb_ff)
        speed = stick_speed(sticks.throttle, cfg)
        roll = self._roll(mode, sticks, pos, nav, cfg)
        a, b = self.line or (pos, pos)
        return AssistedDemand(Setpoint(Kind.LINE, a, b, self.alt, speed=speed), roll, climb)

    def _roll(
        self, mode: FlightMode, sticks: Sticks, pos: tuple[float, float], nav: NavState,
        cfg: FlightConfig,
    ) -> float:  # fmt: skip
        """The bank angle asked for, or NaN to follow the held track (Position)."""
        if not centred(sticks.roll):
            self.line = None
            return sticks.roll * cfg.roll_limit
        if mode != FlightMode.POSITION:
            return 0.0
        if self.line is None:
            if abs(nav.roll_rad) > LEVEL_RAD:
                return 0.0  # level the wings first, then take the track they give
            self.line = (pos, track_ahead(pos, nav))
        return math.nan
