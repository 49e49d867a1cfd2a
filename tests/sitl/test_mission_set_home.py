"""A QGroundControl plan that moves home on the way (DO_SET_HOME, its "Set launch location"),
flown whole with the c172p through MAVSDK: after the item the vehicle's home is the plan's
point (HOME_POSITION, which QGroundControl's map shows), the mission flies on to its next
waypoint rather than starting again, and its Return to Launch brings the aircraft back to
the new home, not to the runway it left."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from companion.geodesy import LocalFrame
from companion.navigation.estimate_csv import read_estimate as read_truth
from mavlink_dialect import companion as d
from tests.sim.sim_run import with_sim
from tests.support.mavsdk_flight import circled, mission_finished, plan_uploaded, until
from tests.support.qgc_plan import simple_item, write_plan

HOME = LocalFrame(-37.9105, 145.1340)
TAKEOFF, A, NEW_HOME, B = (0.0, 600.0), (900.0, 900.0), (1500.0, -1500.0), (0.0, -600.0)


def _plan(path: Path) -> Path:
    def at(ne: tuple[float, float], alt: float) -> list:
        return [*HOME.latlon(*ne), alt]

    items = [
        simple_item(d.MAV_CMD_NAV_TAKEOFF, 3, [15, 0, 0, None, *at(TAKEOFF, 60.0)], 1),
        simple_item(d.MAV_CMD_NAV_WAYPOINT, 3, [0, 0, 0, None, *at(A, 100.0)], 2),
        simple_item(d.MAV_CMD_DO_SET_HOME, 3, [0, 0, 0, None, *at(NEW_HOME, 0.0)], 3),
        simple_item(d.MAV_CMD_NAV_WAYPOINT, 3, [0, 0, 0, None, *at(B, 100.0)], 4),
        simple_item(d.MAV_CMD_NAV_RETURN_TO_LAUNCH, 2, [0, 0, 0, 0, 0, 0, 0], 5),
    ]
    return write_plan(path, items, (-37.9105, 145.134, 126))


async def _fly(port: int, plan: str) -> dict:
    seen: dict = {}
    async with plan_uploaded(port, plan) as flight:
        first = await anext(aiter(flight.telemetry.subscribe_home()))
        seen["first_home_alt"] = first.absolute_altitude_m
        await flight.action.arm()
        await flight.mission.start_mission()
        moved = await until(flight.telemetry.subscribe_home(),
                            lambda h: math.dist(HOME.ne(h.latitude_deg, h.longitude_deg),
                                                NEW_HOME) < 1.0, "the new home", 200)  # fmt: skip
        seen["home_alt"] = moved.absolute_altitude_m
        progress = await anext(aiter(flight.mission.subscribe_mission_progress()))
        seen["current_after_home"] = progress.current
        seen["finished"] = await mission_finished(flight.mission, 200)

        await circled(flight, (HOME, NEW_HOME), 400.0, 60.0)  # the truth's last 40 s there
    return seen


@pytest.mark.timeout(400)
def test_a_plans_set_home_moves_home_and_return_flies_there(tmp_path):
    plan = _plan(tmp_path / "set_home.plan")
    seen, out, truth_path = with_sim(tmp_path, lambda port: _fly(port, str(plan)))
    assert seen["finished"], out[-3000:]
    # Once: the mission goes on from the item after it, not the commander's last word.
    assert out.count("mission item 2: home set at the plan's point") == 1, out[-3000:]
    # Its altitude: 0 m above the old home (a relative frame), as QGroundControl wrote it.
    assert abs(seen["home_alt"] - seen["first_home_alt"]) < 0.5, seen
    assert seen["current_after_home"] >= 3, seen  # flying on to B, not started again
    truth = read_truth(truth_path)
    ne = np.array([HOME.ne(la, lo) for la, lo in zip(truth["lat"], truth["lon"], strict=True)])
    t = np.array(truth["t"])
    last = ne[t > t[-1] - 40.0]  # the last 40 s: circling after the Return
    away = np.hypot(last[:, 0] - NEW_HOME[0], last[:, 1] - NEW_HOME[1])
    assert away.max() < 400.0, away.max()
    assert np.hypot(last[:, 0], last[:, 1]).min() > 1_500.0  # not back over the runway
