"""Return flies to the plan's rally point when it is nearer than home, and circles it at its
own height, as an ArduPlane or PX4 user expects; home when home is nearer. A mission's own
NAV_RETURN_TO_LAUNCH item enters Return too.

The square plan's rally point is 900 m east and 100 m south of home, 80 m above it. From
the square's north-east corner (1.8 km east of home) the rally point is the nearer; from
its last leg, home. Lockstep JSBSim; the track is judged by the simulator's truth.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from companion.control.mission.plan import checked_plan
from companion.geodesy import LocalFrame
from mavlink_dialect import companion as d
from tests.support.vehicle import REPO, set_param, wait_for

PLAN = REPO / "qgc_plans" / "square.plan"
pytestmark = pytest.mark.vehicle(plan=str(PLAN))
HOME = LocalFrame(-37.9105, 145.134)  # the plan's home, where the simulation starts
HOME_ALT = 80.0  # the runway, m above sea level
_RALLY = checked_plan(PLAN)[d.MAV_MISSION_TYPE_RALLY][0]
RALLY = HOME.ne(_RALLY.x / 1e7, _RALLY.y / 1e7)
CIRCLING_S = 60.0  # judged over this much flight once the aircraft is there


def _told(sim) -> str:
    """What the vehicle said of where Return goes (perhaps heard with the command's ack)."""
    w = sim.watcher

    def said(_msg: object) -> str | None:
        return next((t for t in w.texts if t.startswith("Return: ")), None)

    return said(None) or w.until(said, 30, "a text saying where Return goes")


def _track(sim, since_s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """North, east (m from home) and height above the runway, from ``since_s`` on."""
    truth = sim.truth()
    keep = np.asarray(truth["t"]) >= since_s
    ne = np.array([HOME.ne(la, lo) for la, lo in zip(truth["lat"], truth["lon"], strict=True)])
    return ne[keep, 0], ne[keep, 1], np.asarray(truth["alt"])[keep] - HOME_ALT


@pytest.mark.timeout(900)
def test_return_from_far_out_circles_the_nearer_rally_point_at_its_height(sim):
    sim.wait_ready()
    sim.arm_and_start()
    sim.run_until_item(1)  # at the square's north-east corner, 1.8 km east of home
    sim.watcher.command(d.MAV_CMD_NAV_RETURN_TO_LAUNCH)
    said = _told(sim)
    assert said.startswith("Return: to rally point 1,"), said
    t0 = sim.run_until_time(0.0)
    # 900 m at 25-30 m/s, the descent from 100 to 80 m, and a turn on to the circle.
    end = sim.run_until_time(t0 + 60.0 + CIRCLING_S)
    wait_for(lambda: sim.truth()["t"][-1] >= end - 1.0, 120, "the truth file written")
    north, east, height = _track(sim, end - CIRCLING_S)
    from_rally = np.hypot(north - RALLY[0], east - RALLY[1])
    from_home = np.hypot(north, east)
    assert from_rally.max() < 300.0, f"not circling the rally point: {from_rally.max():.0f} m"
    assert from_home.min() > 600.0, "it went home"
    assert abs(float(np.median(height)) - _RALLY.z) < 10.0, np.median(height)


@pytest.mark.timeout(900)
def test_return_from_the_last_leg_goes_home_and_circles_at_the_loiter_altitude(sim):
    """Home is nearer than the rally point. QGroundControl's Safety page (PX4's) sets the
    loiter altitude as RTL_DESCEND_ALT: home is flown to at the return altitude
    (RTL_ALT_M, 100 m) and circled at the loiter altitude, 60 m, as a PX4 user expects."""
    sim.wait_ready()
    set_param(sim.watcher, "RTL_DESCEND_ALT", 60.0)
    sim.arm_and_start()
    sim.run_until_item(3)  # on the last leg, back towards home from the north
    sim.watcher.command(d.MAV_CMD_NAV_RETURN_TO_LAUNCH)
    assert _told(sim) == "Return: home, nearer than any rally point"
    t0 = sim.run_until_time(0.0)
    end = sim.run_until_time(t0 + 60.0 + CIRCLING_S)
    wait_for(lambda: sim.truth()["t"][-1] >= end - 1.0, 120, "the truth file written")
    north, east, height = _track(sim, end - CIRCLING_S)
    assert math.hypot(float(np.median(north)), float(np.median(east))) < 300.0
    assert abs(float(np.median(height)) - 60.0) < 5.0, np.median(height)  # 61.2 m flown
    assert height.min() > 50.0, height.min()


@pytest.mark.timeout(900)
def test_the_missions_own_return_item_enters_return_and_goes_where_return_goes(sim):
    """The square ends on NAV_RETURN_TO_LAUNCH: reached as it begins, then the mode is
    Return (as ArduPlane and PX4 switch to theirs), said with why and where. Home is the
    nearer from the last waypoint, so the aircraft circles home, in Return."""
    sim.wait_ready()
    sim.arm_and_start()
    sim.run_until_item(5)
    sim.run_until_mode("RTL", timeout_s=60.0)
    w = sim.watcher
    w.until(lambda _m: "Mission: item 5 returns to launch" in w.texts, 30, "why Return")
    assert _told(sim) == "Return: home, nearer than any rally point"
    t0 = sim.run_until_time(0.0)
    end = sim.run_until_time(t0 + 60.0 + CIRCLING_S)
    assert sim.mode() == "RTL"
    wait_for(lambda: sim.truth()["t"][-1] >= end - 1.0, 120, "the truth file written")
    north, east, height = _track(sim, end - CIRCLING_S)
    assert math.hypot(float(np.median(north)), float(np.median(east))) < 300.0
    assert abs(float(np.median(height)) - 100.0) < 15.0  # RTL_ALT_M
