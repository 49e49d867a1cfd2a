"""A landing judged from the simulator's truth: where and how hard it touched down.

Touchdown is the first time after the flight that a wheel carries weight, by JSBSim's own
contact (the ``on_wheels`` column: the simulator writes it beside the truth file,
``bridges/jsbsim/truth_log.py``). Without it, it is judged from the centre of gravity's
height above MSL: the aircraft resting on its wheels before the take-off gives the height
that means "on the runway", and touchdown is the first time after the flight that the
aircraft comes within ``TOUCH_M`` of it and no longer sinks. That counts a C172 skimming
0.3-0.4 m above the runway in its flare as down, 15-20 m before its wheels touch.
The runway is the landing's centreline (from the final approach point through the
landing point) ``RUNWAY_HALF_WIDTH_M`` either side, from the landing point on.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from pyulog import ULog

from bridges.jsbsim.truth_log import wheels_path
from companion.control.mission.items import MissionItem
from companion.control.mission.plan import checked_plan
from companion.geodesy import LocalFrame
from companion.navigation.estimate_csv import read_estimate
from mavlink_dialect import companion as d

TOUCH_M = 0.6  # this close to the resting height and no longer sinking: on the wheels
SETTLED_M_S = 0.15  # m/s down: no longer sinking
SINK_WINDOW_S = 0.3  # the touchdown's vertical speed: the most in this time before it
AIRBORNE_M = 10.0  # the flight proper: higher than this above the runway
RUNWAY_HALF_WIDTH_M = 15.0
RUNWAY_LENGTH_M = 1500.0
STOPPED_M_S = 0.5

# The criteria: issue 24's, the along and across tightened by issue 42 (item 8).
MAX_ALONG_M, MAX_ACROSS_M, MAX_SINK_M_S, MAX_BOUNCE_M, MAX_BANK_DEG = 15.0, 2.0, 1.5, 1.0, 10.0


@dataclass(frozen=True)
class LandingScore:
    """What a user would judge a landing by."""

    landed: bool
    along_m: float = math.nan  # touchdown past (+) or short of (-) the landing point
    across_m: float = math.nan  # touchdown right (+) of the centreline
    sink_m_s: float = math.nan  # vertical speed at touchdown
    bounce_m: float = math.nan  # highest the wheels rose after touching
    bank_deg: float = math.nan  # bank at touchdown
    stop_along_m: float = math.nan  # where it stopped, along the runway from the point
    stop_across_m: float = math.nan
    stopped: bool = False
    on_runway: bool = False

    def passed(self, max_along_m: float = MAX_ALONG_M, max_across_m: float = MAX_ACROSS_M) -> bool:
        """Every criterion met (disarming is judged by the caller); the along and across
        limits are issue 42's unless a caller names looser ones."""
        return (
            self.landed
            and abs(self.along_m) <= max_along_m
            and abs(self.across_m) <= max_across_m
            and self.sink_m_s <= MAX_SINK_M_S
            and self.bounce_m <= MAX_BOUNCE_M
            and abs(self.bank_deg) <= MAX_BANK_DEG
            and self.stopped
            and self.on_runway
        )

    def as_row(self) -> dict[str, float | bool]:
        return asdict(self)


def landing_line(items: list[MissionItem]) -> tuple[tuple[float, float], tuple[float, float]]:
    """The last NAV_LAND's point and the point the approach to it starts from (lat, lon)."""
    for k in range(len(items) - 1, 0, -1):
        if items[k].command == d.MAV_CMD_NAV_LAND:
            land = (items[k].x / 1e7, items[k].y / 1e7)
            prev = next(
                it for it in reversed(items[:k]) if it.x or it.y
            )  # the final approach point
            return (prev.x / 1e7, prev.y / 1e7), land
    raise ValueError("the plan has no NAV_LAND")


def score_landing(
    truth: dict[str, np.ndarray],
    approach: tuple[float, float],
    land: tuple[float, float],
    loiter_radius_m: float = 0.0,
    clockwise: bool = True,
) -> LandingScore:
    """Score the landing in ``truth`` on the line ``approach`` → ``land`` (lat, lon).

    When the approach point is a LOITER_TO_ALT centre, the line starts at its tangent
    point: give the radius (and direction) to have it found.
    """
    line = (approach, land, loiter_radius_m, clockwise)
    along, across = line_coordinates(truth["lat"], truth["lon"], *line)
    alt = truth["alt"]
    rest = float(alt[0])
    height = alt - rest
    flying = np.nonzero(height > AIRBORNE_M)[0]
    if flying.size == 0:
        return LandingScore(False)
    speed = np.hypot(truth["vn"], truth["ve"])
    end = _first_stop(height, speed, int(flying[0]))
    flying = flying[flying <= end]
    vd = truth["vd"]
    if "on_wheels" in truth:
        low = truth["on_wheels"] > 0.5
    else:
        # The wheels meet the runway where the descent stops close to it (a tail dragger on
        # its main wheels sits higher than at rest, in its three-point attitude).
        low = (height < TOUCH_M) & (vd < SETTLED_M_S)
    after = flying[-1] + np.nonzero(low[flying[-1] : end + 1])[0]
    if after.size == 0:
        return LandingScore(False)
    k = int(after[0])
    stopped = bool(speed[end] < STOPPED_M_S)
    on_runway = bool(
        abs(across[end]) <= RUNWAY_HALF_WIDTH_M and -50.0 <= along[end] <= RUNWAY_LENGTH_M
    )
    return LandingScore(
        True,
        float(along[k]),
        float(across[k]),
        float(
            np.max(
                vd[(truth["t"] >= truth["t"][k] - SINK_WINDOW_S) & (truth["t"] <= truth["t"][k])]
            )
        ),
        float(np.max(height[k : end + 1]) - height[k]),
        float(math.degrees(truth["roll"][k])),
        float(along[end]),
        float(across[end]),
        stopped,
        on_runway,
    )


def line_coordinates(
    lat: np.ndarray,
    lon: np.ndarray,
    approach: tuple[float, float],
    land: tuple[float, float],
    loiter_radius_m: float = 0.0,
    clockwise: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """Metres along (+ past the landing point) and across (+ right of) the landing line
    ``approach`` → ``land`` (lat, lon; the loiter as for ``score_landing``)."""
    frame = LocalFrame(*land)
    n, e = frame.ne(lat, lon)
    a = frame.ne(*approach)
    if loiter_radius_m > 0.0:
        a = _tangent_point(a, loiter_radius_m, clockwise)
    heading = math.atan2(-a[1], -a[0])
    u = (math.cos(heading), math.sin(heading))
    return n * u[0] + e * u[1], -n * u[1] + e * u[0]


def _first_stop(height: np.ndarray, speed: np.ndarray, took_off: int) -> int:
    """Where the aircraft first stands still on the ground after ``took_off`` (the last
    sample if it never does): the end of the landing.

    A simulator left running once the vehicle has disarmed keeps integrating a parked
    aircraft nobody flies (one sat pitching on its gear for 100 s, then tumbled); that is
    not part of the landing.
    """
    still = np.nonzero((speed < STOPPED_M_S) & (height < TOUCH_M))[0]
    still = still[still > took_off]
    return int(still[0]) if still.size else len(height) - 1


def _tangent_point(
    centre: tuple[float, float], radius: float, clockwise: bool
) -> tuple[float, float]:
    """Where a circle round ``centre`` is left straight for the origin (the land point)."""
    dist = math.hypot(*centre)
    if dist <= radius:
        return centre
    bearing = math.atan2(-centre[1], -centre[0])
    beta = math.acos(radius / dist)
    angle = bearing - beta if clockwise else bearing + beta
    return (centre[0] + radius * math.cos(angle), centre[1] + radius * math.sin(angle))


def read_truth(path: str | Path) -> dict[str, np.ndarray]:
    """A truth file's columns, with ``on_wheels`` (1: a wheel carries weight) at each row
    when the simulator wrote the wheel contacts beside it."""
    truth = read_estimate(path)
    wheels = wheels_path(path)
    rows = wheels.read_text().split()[1:] if wheels.exists() else []
    if rows:
        changes = np.array([[float(v) for v in row.split(",")] for row in rows])
        at = np.searchsorted(changes[:, 0], truth["t"] + 1e-6, side="right") - 1
        truth["on_wheels"] = np.where(at >= 0, changes[np.maximum(at, 0), 1], np.nan)
    return truth


def landing_score_for_plan(truth: dict[str, np.ndarray], items: list[MissionItem]) -> LandingScore:
    """``score_landing`` on the plan's last landing (its final approach as planned)."""
    return score_landing(truth, *plan_line(items))


def plan_line(
    items: list[MissionItem],
) -> tuple[tuple[float, float], tuple[float, float], float, bool]:
    """The plan's last landing line as ``score_landing`` takes it: approach, land point,
    and the radius and direction of a LOITER_TO_ALT left on its tangent (0: none)."""
    approach, land = landing_line(items)
    final = next(it for it in reversed(items) if it.command != d.MAV_CMD_NAV_LAND and it.x)
    radius, clockwise = 0.0, True
    if final.command == d.MAV_CMD_NAV_LOITER_TO_ALT and final.param1 >= 0.5:
        radius, clockwise = abs(final.param2), final.param2 >= 0
    return approach, land, radius, clockwise


def navigation_across(truth: Path, plan: Path, s: LandingScore) -> float:
    """Where the vehicle's own navigation solution put it across the line at the touchdown
    (its flight log beside ``truth``): what the landing law steered by; the rest of
    ``s.across_m`` is the navigation's error. NaN: no landing or no log."""
    log = truth.parent / "flight.ulg"
    if not s.landed or not log.exists():
        return float("nan")
    t = read_truth(truth)
    line = plan_line(checked_plan(plan)[0])
    along, across = line_coordinates(t["lat"], t["lon"], *line)
    at = np.nonzero((along == s.along_m) & (across == s.across_m))[0]
    nav = ULog(str(log), ["nav_state"]).get_dataset("nav_state").data
    _, nav_across = line_coordinates(nav["lat_deg"], nav["lon_deg"], *line)
    k = np.searchsorted(nav["timestamp"] / 1e6, t["t"][at[0]])
    return float(nav_across[min(k, len(nav_across) - 1)])
