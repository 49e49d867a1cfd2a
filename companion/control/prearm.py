"""Pre-arm checks: what must hold before the aircraft may be armed, as ArduPilot and PX4 ask.

Pure: the newest navigation solution and sensor samples (with their own time stamps),
the vehicle time, the mode and the stored lists in; the reasons arming is refused out,
each worded for a ``PreArm: ...`` STATUSTEXT. The link refuses the arm command with them
(MAV_RESULT_DENIED) and shows the result in SYS_STATUS; the supervisor adds the checks that
need the flight plug-ins' devices (``Plugin.prearm``). ``ARMING_CHECK`` 0 turns them off for
the bench, and force arming (param2 21196) skips them, as in ArduPilot and PX4.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from companion.control.mission.fence import Fence
from companion.control.mission.items import MissionItem, check_mission
from companion.messages import (
    Baro,
    Compass,
    FlightMode,
    GpsFix,
    Imu,
    Magnetometer,
    NavFlags,
    NavState,
)
from companion.params import ParamDecl
from mavlink_dialect import companion as d

FORCE_ARM = 21196  # param2 of COMPONENT_ARM_DISARM that skips the checks
PREFIX = "PreArm: "
PREARM_PARAMS = (
    ParamDecl.switch("ARMING_CHECK", 1.0, "pre-arm checks (0: none, for the bench)", "None", "All"),
    ParamDecl("ARMING_GPS_EPH", 5.0, 0.5, 100.0, "m", "worst GPS horizontal accuracy to arm"),
    ParamDecl("ARMING_STALE_S", 1.0, 0.1, 10.0, "s", "a sensor older than this is not fresh"),
)
_NAV_OK = int(NavFlags.ATTITUDE_VALID | NavFlags.POSITION_VALID | NavFlags.VELOCITY_VALID)


@dataclass
class Readiness:
    """What the checks look at: the newest samples as the bus has them."""

    now_us: int
    nav: NavState | None = None
    gps: GpsFix | None = None
    imu: Imu | None = None
    # None: the vehicle has no such sensor (or it has never spoken), which is no failure;
    # the navigator says whether it can fly without it.
    mag: Magnetometer | None = None
    compass: Compass | None = None
    baro: Baro | None = None
    mode: FlightMode = FlightMode.LOITER
    mission: list[MissionItem] = field(default_factory=list)
    fence: list[MissionItem] = field(default_factory=list)
    devices: list[str] = field(default_factory=list)  # silent or garbled (DeviceWatch)


class PlanVerdicts:
    """Whether the stored mission and fence are valid, judged once per stored list.

    The link asks every second, and a fence polygon's simple-polygon check is quadratic in
    its vertices (6-9 ms for 100 here). A stored list is replaced when the plan changes,
    never changed in place (``MissionStore``), so the list itself is the key; holding it
    keeps its identity from being reused.
    """

    def __init__(self) -> None:
        self._mission: tuple[list[MissionItem], bool] | None = None
        self._fence: tuple[list[MissionItem], Fence, bool] | None = None

    def mission_valid(self, items: list[MissionItem]) -> bool:
        """Whether the mission would be accepted from a ground station."""
        if self._mission is None or self._mission[0] is not items:
            self._mission = (items, check_mission(items) == d.MAV_MISSION_ACCEPTED)
        return self._mission[1]

    def fence(self, items: list[MissionItem]) -> tuple[Fence, bool]:
        """The fence the items make, and whether every zone of it has a valid shape."""
        if self._fence is None or self._fence[0] is not items:
            fence = Fence.from_items(items)
            zones = [*fence.inclusions, *fence.exclusions]
            valid = not fence.empty and all(z.is_valid for z in zones)
            self._fence = (items, fence, valid)
        return self._fence[1], self._fence[2]


def failures(
    r: Readiness, params: dict[str, float], plans: PlanVerdicts | None = None
) -> list[str]:
    """Every reason arming is refused now (empty: ready), each without the prefix.
    ``plans`` keeps the plans' verdicts between calls (a fresh one judges them now)."""
    plans = plans or PlanVerdicts()
    fresh = [*_fresh(r, params), *r.devices]
    return [*_navigation(r), *_gps(r, params), *fresh, *_plans(r, plans)]


def _navigation(r: Readiness) -> list[str]:
    nav = r.nav
    if nav is None:
        return ["navigation not running"]
    if nav.flags & NavFlags.ALIGNING:
        return ["navigation still aligning"]
    if nav.flags & _NAV_OK != _NAV_OK or nav.flags & NavFlags.DEAD_RECKONING:
        return ["navigation unhealthy"]
    return []


def _gps(r: Readiness, params: dict[str, float]) -> list[str]:
    gps = r.gps
    if gps is None or gps.fix_type < 3:
        return ["GPS: no 3D fix"]
    eph, limit = gps.eph_m, params["ARMING_GPS_EPH"]
    if math.isfinite(eph) and eph > limit:
        return [f"GPS: accuracy {eph:.1f} m, need {limit:g} m"]
    return []


def _fresh(r: Readiness, params: dict[str, float]) -> list[str]:
    """Every sensor the vehicle has, fresh: one that stopped is not flown on."""
    stale_us = params["ARMING_STALE_S"] * 1e6
    found = []
    samples = (
        ("navigation", r.nav), ("GPS", r.gps), ("IMU", r.imu), ("magnetometer", r.mag),
        ("compass", r.compass), ("barometer", r.baro),
    )  # fmt: skip
    for name, sample in samples:
        if sample is not None and r.now_us - int(sample.t_us) > stale_us:
            found.append(f"{name} not fresh")
    return found


def _plans(r: Readiness, plans: PlanVerdicts) -> list[str]:
    found = []
    if r.mode == FlightMode.MISSION:
        if not r.mission:
            found.append("Mission: none stored")
        elif not plans.mission_valid(r.mission):
            found.append("Mission: not valid")
    if r.fence:
        fence, valid = plans.fence(r.fence)
        if not valid:
            found.append("Fence: not valid")
        elif r.nav is not None and r.nav.flags & NavFlags.POSITION_VALID:
            breach = fence.breach(r.nav.lat_deg, r.nav.lon_deg)
            if breach is not None:
                found.append(f"Fence: {breach}")
    return found
