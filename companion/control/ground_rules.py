"""What an armed fixed wing on the ground does with each mode, and what the operator is told.

A fixed wing cannot circle, go to a point or return while it stands on the runway, and a
mission without a take-off item gave it nothing to fly: both used to leave it armed and
silent (MAVSDK's mission.py waited for ever). The rules:
- Mission: flown. When the first item to fly is not a NAV_TAKEOFF the aircraft takes off
  along the runway first (an implicit take-off, ``MissionExecutor.take_off_first``) and
  then flies to that item; a STATUSTEXT says so. PX4's MIS_TAKEOFF_REQ would refuse the
  start instead; MAVSDK's mission plug-in never adds a take-off, so its scripts could
  then not fly at all.
- Loiter, Guided (go to, orbit) and Return, asked for by a command while armed on the
  ground: refused, with the reason (take off first). Failsafes and the pilot's switch are
  not refused; the controller idles on the ground in these modes.
- Armed on the ground in one of them (the vehicle starts in Loiter): a STATUSTEXT says
  the aircraft holds on the ground until Takeoff or Mission.
"""

from __future__ import annotations

import math

from companion.control.flight.on_ground import AIRBORNE_AGL_M, LANDED_SPEED
from companion.control.mission.items import DO_COMMANDS, MissionItem
from companion.control.modes import BY_MODE
from companion.messages import FlightMode, NavState
from mavlink_dialect import companion as d

AIRBORNE_ONLY = frozenset({FlightMode.LOITER, FlightMode.GUIDED, FlightMode.RTL})
_NAV_FIRST_LIMIT = 1000  # items looked through for the first one to fly (DO_JUMPs loop)


def name(mode: FlightMode) -> str:
    """The mode as ground stations name it."""
    return BY_MODE[mode].name


def refusal(mode: FlightMode) -> str:
    """Why a command for ``mode`` is refused while armed on the ground."""
    return f"{name(mode)}: on the ground, take off first"


def standing(nav: NavState | None, home_alt_msl: float | None) -> bool | None:
    """Whether the aircraft stands on the ground by the flight controller's own measure
    (near home's height, slower than a fixed wing flies), for the moments after arming
    before the controller has said so; None when there is no solution or home yet."""
    if nav is None or home_alt_msl is None:
        return None
    slow = math.hypot(nav.vn_m_s, nav.ve_m_s) < LANDED_SPEED
    return slow and nav.alt_msl_m - home_alt_msl < AIRBORNE_AGL_M


def first_to_fly(items: list[MissionItem], first: int) -> MissionItem | None:
    """The first item from ``first`` the aircraft would fly (DO items and jumps passed)."""
    seq = first
    for _ in range(_NAV_FIRST_LIMIT):
        if not 0 <= seq < len(items):
            return None
        item = items[seq]
        if item.command == d.MAV_CMD_DO_JUMP:
            seq = round(item.param1)
        elif item.command in DO_COMMANDS:
            seq += 1
        else:
            return item
    return None


def ground_notice(mode: FlightMode, items: list[MissionItem], first: int) -> str | None:
    """What to tell the operator on arming, or on a mode entered, armed on the ground (in
    STATUSTEXT's 50 bytes, so every ground station shows it whole)."""
    if mode in AIRBORNE_ONLY:
        return f"{name(mode)}: on the ground until Takeoff or Mission"
    if mode != FlightMode.MISSION:
        return None
    item = first_to_fly(items, first)
    if item is None or item.command in (d.MAV_CMD_NAV_TAKEOFF, d.MAV_CMD_NAV_LAND):
        return None
    return f"Mission item {item.seq} not a take-off: taking off first"
