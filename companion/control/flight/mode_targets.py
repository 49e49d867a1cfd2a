"""The setpoint a mode other than Mission flies when it is entered: take-off to a height,
Return home (or to the rally point the commander chose), go to or circle a point,
straight on for a pilot's mode without fresh sticks, else circle where the aircraft is;
and the circle a return, a go-to or a take-off turns into on arrival (``arrive``)."""

from __future__ import annotations

import math

from companion.control.flight.assisted import track_ahead
from companion.control.flight.flight_params import FlightConfig
from companion.control.mission.executor import Kind, Setpoint
from companion.control.mission.leg_geometry import past_point
from companion.control.modes import PILOT_MODES
from companion.geodesy import LocalFrame
from companion.messages import FlightMode, NavState, VehicleStatus


def mode_target(
    mode: FlightMode,
    status: VehicleStatus,
    pos: tuple[float, float],
    nav: NavState,
    where: tuple[LocalFrame | None, float],
    config: FlightConfig,
) -> Setpoint:
    """What a mode other than Mission flies when entered at ``pos``; ``where``: the local
    frame about home and home's height (m MSL)."""
    frame, home_alt = where
    assert frame is not None
    radius = config["WP_LOITER_RAD"]
    alt = nav.alt_msl_m
    if mode == FlightMode.TAKEOFF:  # to the height asked for, else the return height
        climb_to = status.target_alt_msl_m
        if not math.isfinite(climb_to):
            climb_to = home_alt + config["RTL_ALT_M"]
        return Setpoint(Kind.TAKEOFF, pos, pos, climb_to)
    if mode == FlightMode.RTL:
        alt = status.target_alt_msl_m  # a rally point's
        if not (_has_target(status) and math.isfinite(alt)):
            alt = home_alt + config["RTL_ALT_M"]
        return Setpoint(Kind.LINE, pos, return_point(status, frame), alt, radius)
    target = (status.target_lat_deg, status.target_lon_deg, status.target_alt_msl_m)
    has_target = math.isfinite(target[0]) and math.isfinite(target[1])
    if math.isfinite(status.target_radius_m) and status.target_radius_m > 0:
        radius = status.target_radius_m  # an orbit's own radius
    if mode in (FlightMode.GUIDED, FlightMode.LOITER) and has_target:
        point = frame.ne(target[0], target[1])
        alt = target[2] if math.isfinite(target[2]) else alt  # NaN: hold the height
        if mode == FlightMode.GUIDED:
            return Setpoint(Kind.LINE, pos, point, alt, radius)
        return Setpoint(Kind.CIRCLE, point, point, alt, radius)
    if mode in PILOT_MODES:  # no fresh sticks: straight on, height held
        return Setpoint(Kind.LINE, pos, track_ahead(pos, nav), alt)
    return Setpoint(Kind.CIRCLE, pos, pos, alt, radius)


def return_point(status: VehicleStatus, frame: LocalFrame | None) -> tuple[float, float]:
    """Where Return flies (local north, east): the commander's rally point, else home."""
    if frame is None or not _has_target(status):
        return (0.0, 0.0)
    return frame.ne(status.target_lat_deg, status.target_lon_deg)


def _has_target(status: VehicleStatus) -> bool:
    return math.isfinite(status.target_lat_deg) and math.isfinite(status.target_lon_deg)


def loiter_alt(status: VehicleStatus, home_alt: float, config: FlightConfig) -> float:
    """The height (m MSL) a return ends circling at: ``RTL_LOITER_ALT_M`` above home when
    it returns home (PX4's RTL_DESCEND_ALT), none (inf) when to a rally point, whose own
    altitude it keeps."""
    return math.inf if _has_target(status) else home_alt + config["RTL_LOITER_ALT_M"]


def arrive(
    sp: Setpoint,
    mode: FlightMode,
    pos: tuple[float, float],
    alt: float,
    config: FlightConfig,
    turn_radius: float,
    loiter_msl: float = math.inf,
) -> Setpoint:
    """Return and go-to circle their point on arrival (a return home descends to
    ``loiter_msl`` when lower than its return altitude); a take-off circles when
    high."""
    radius = config["WP_LOITER_RAD"]
    reach = max(radius, turn_radius) * 1.5
    near = math.hypot(sp.b[0] - pos[0], sp.b[1] - pos[1]) < reach
    # Passing the point counts too: the line goes on past it for ever.
    arrived = near or past_point(sp.a, sp.b, pos)
    if sp.kind == Kind.LINE and mode in (FlightMode.RTL, FlightMode.GUIDED) and arrived:
        circle_alt = min(sp.alt_msl, loiter_msl) if mode == FlightMode.RTL else sp.alt_msl
        return Setpoint(Kind.CIRCLE, sp.b, sp.b, circle_alt, radius)
    if sp.kind == Kind.TAKEOFF and alt >= sp.alt_msl - 5.0:
        return Setpoint(Kind.CIRCLE, pos, pos, sp.alt_msl, radius)
    return sp
