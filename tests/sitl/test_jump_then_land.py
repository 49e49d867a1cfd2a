"""A take-off, a DO_JUMP loop flown three times, then QGroundControl's landing pattern.

qgc_plans/jump_land.plan as a user makes it in QGroundControl: NAV_TAKEOFF east along the
runway, a triangle of three waypoints, "Jump to item" 2 (the first waypoint) repeated
twice, then the fixed-wing landing pattern back onto the runway (DO_LAND_START, the camera
stops, LOITER_TO_ALT, NAV_LAND). Flown by the whole vehicle in exact lockstep, started by
the simulator, as the campaigns and benchmarks/landing.py fly (ground/campaign/flight_run:
its own bus namespace, UDP port and state directory, everything ended and cleaned after).

Judged as the ground station sees it: MISSION_ITEM_REACHED for the take-off, the triangle
three times, the landing circle and the landing point, in that order and nothing else;
MISSION_CURRENT following the same items; then, from the simulator's truth, the touchdown
on the landing point (as tests/sitl/test_landing_on_target.py judges it) and the vehicle
disarming itself. benchmarks/jump_landings.py flies many such plans.
"""

from __future__ import annotations

import json
import os

import pytest

from companion.bus.namespace import SHM_DIR
from companion.control.mission.plan import checked_plan
from ground.campaign.flight_run import FlightJob, fly_flight
from ground.campaign.landing_score import landing_score_for_plan, read_truth
from ground.campaign.spec import SIM_CONFIG, Flight
from tests.support.vehicle import REPO

PLAN = REPO / "qgc_plans" / "jump_land.plan"
LAPS = [1, 2, 3] * 3  # the triangle, and twice more by the DO_JUMP (item 4)
ORDER = [0, *LAPS, 8, 9]  # take-off, the laps, LOITER_TO_ALT, NAV_LAND
MAX_ALONG_M, MAX_ACROSS_M, MAX_SINK_M_S = 15.0, 3.0, 1.5  # across: the GPS's wander too
# A hang guard only (wall seconds): about 11 simulated minutes, 2-3 wall minutes alone;
# beside other simulations on two cores much longer.
WALL_LIMIT_S = 2400.0


@pytest.mark.timeout(2700)
def test_the_loop_is_flown_three_times_then_the_aircraft_lands_on_the_point(tmp_path):
    flight = Flight(str(PLAN), "c172p", (0.0, 0.0, 0.0), "none", (), 1, str(SIM_CONFIG),
                    False, 1200.0, 10.0)  # fmt: skip
    row = fly_flight(FlightJob(flight, str(tmp_path), timeout_s=WALL_LIMIT_S))
    folder = tmp_path / flight.flight_id
    timeline = (folder / "timeline.json").read_text()
    assert row["status"] == "ok", (row, timeline)
    assert row["completed"] and not row["failsafes"], row
    assert row["armed_at_end"] is False, row  # landed, stopped and disarmed itself
    # Nothing of the flight left running or in shared memory (its namespace is campPIDpPORT).
    assert not list(SHM_DIR.glob(f"cmp_camp{os.getpid()}p*")), "shared memory left behind"
    seen = json.loads(timeline)
    assert seen["reached"] == ORDER, seen
    # MISSION_CURRENT from the start: item 0 until the climb ends, then never back to it.
    assert seen["seqs"] == ORDER, seen
    score = landing_score_for_plan(read_truth(folder / "truth.csv"), checked_plan(PLAN)[0])
    assert score.landed and score.stopped and score.on_runway, score
    assert abs(score.along_m) <= MAX_ALONG_M, score
    assert abs(score.across_m) <= MAX_ACROSS_M, score
    assert score.sink_m_s <= MAX_SINK_M_S, score
