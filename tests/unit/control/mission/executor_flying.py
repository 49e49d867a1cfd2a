"""Building missions and teleporting the aircraft along them, for the executor tests."""

from __future__ import annotations

import math

from companion.actuators.airframe import load_airframe
from companion.control.flight.controller import FlightController
from companion.control.flight.flight_params import control_params, flight_config
from companion.control.mission.executor import (
    ExecutorConfig,
    Kind,
    MissionExecutor,
    Setpoint,
)
from companion.control.mission.items import MissionItem, check_mission
from companion.geodesy import LocalFrame
from companion.messages import FlightMode, NavFlags, NavState, VehicleStatus
from mavlink_dialect import companion as d

HOME = LocalFrame(-37.9105, 145.1340)
HOME_ALT = 80.0
REL = d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT


def item(
    seq: int,
    command: int,
    ne: tuple[float, float] | None = None,
    z: float = 0.0,
    p1: float = 0.0,
    p2: float = 0.0,
    p3: float = 0.0,
) -> MissionItem:
    """A MISSION_ITEM_INT at ``ne`` metres from home (None: no position)."""
    x = y = 0
    if ne is not None:
        lat, lon = HOME.latlon(*ne)
        x, y = round(lat * 1e7), round(lon * 1e7)
    return MissionItem(seq, REL, command, 0, 1, p1, p2, p3, 0.0, x, y, z)


def wp(seq: int, ne: tuple[float, float], z: float = 100.0, radius: float = 0.0) -> MissionItem:
    return item(seq, d.MAV_CMD_NAV_WAYPOINT, ne, z, p2=radius)


def jump(seq: int, target: int, repeats: int) -> MissionItem:
    return item(seq, d.MAV_CMD_DO_JUMP, p1=target, p2=repeats)


def speed(seq: int, m_s: float) -> MissionItem:
    return item(seq, d.MAV_CMD_DO_CHANGE_SPEED, p1=0, p2=m_s, p3=-1)


def executor(
    items: list[MissionItem],
    pos: tuple[float, float] = (0.0, 0.0),
    alt: float = HOME_ALT + 100.0,
    config: ExecutorConfig | None = None,
) -> MissionExecutor:
    assert check_mission(items) == d.MAV_MISSION_ACCEPTED  # only plans the vehicle takes
    ex = MissionExecutor(items, HOME, HOME_ALT, config or ExecutorConfig())
    ex.start(0, pos, alt)
    return ex


def dist(a: tuple[float, float], b: tuple[float, float]) -> float:
    return math.hypot(b[0] - a[0], b[1] - a[1])


def towards(pos: tuple[float, float], to: tuple[float, float], step: float) -> tuple[float, float]:
    gap = dist(pos, to)
    if gap <= step:
        return to
    return pos[0] + (to[0] - pos[0]) * step / gap, pos[1] + (to[1] - pos[1]) * step / gap


def on_circle(centre: tuple[float, float], radius: float, deg: float) -> tuple[float, float]:
    a = math.radians(deg)
    return centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a)


def fly_lines(
    ex: MissionExecutor,
    pos: tuple[float, float] = (0.0, 0.0),
    step_m: float = 5.0,
    turn_radius: float = 0.0,
    max_steps: int = 20_000,
) -> tuple[list[int], list[Setpoint], tuple[float, float]]:
    """Teleport towards each LINE's end until the executor finishes or gives a circle.

    Returns the items reached (in order, from every drain), the setpoints and where the
    aircraft ended.
    """
    reached: list[int] = []
    setpoints: list[Setpoint] = []
    for t in range(max_steps):
        sp = ex.step(pos, sp_alt(setpoints), float(t), turn_radius)
        setpoints.append(sp)
        reached += ex.drain_reached()
        if ex.finished or sp.kind != Kind.LINE:
            return reached, setpoints, pos
        pos = towards(pos, sp.b, step_m)
    raise AssertionError("the mission never finished")


def sp_alt(setpoints: list[Setpoint]) -> float:
    """The altitude the aircraft is at: the last one it was asked for."""
    return setpoints[-1].alt_msl if setpoints else HOME_ALT + 100.0


# --- take-off ------------------------------------------------------------------------------


def cruising(items: list[MissionItem]) -> tuple[FlightController, NavState, VehicleStatus]:
    """A c172p's controller flying ``items`` in Mission from home, and a solution 100 m up
    just east of home, flying east at 25 m/s."""
    decls = control_params(load_airframe("c172p").control)
    controller = FlightController(flight_config({p.name: p.default for p in decls}), items)
    status = VehicleStatus(mode=int(FlightMode.MISSION), armed=1, home_valid=1)
    status.home_lat_deg, status.home_lon_deg, status.home_alt_msl_m = -37.9105, 145.134, HOME_ALT
    nav = NavState(flags=int(NavFlags.POSITION_VALID), lat_deg=-37.9105, lon_deg=145.1343)
    nav.alt_msl_m, nav.ve_m_s = HOME_ALT + 100.0, 25.0
    return controller, nav, status
