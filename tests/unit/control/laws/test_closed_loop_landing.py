"""Landings flown by the control laws against JSBSim on the true state (closed_loop.py).

The benchmark's plan (take off east, a loop, then QGroundControl's landing pattern back
onto the runway) scored as the issue asks, from the simulator's state: touchdown within
15 m along and 2 m across the landing point, at most 1.5 m/s down, no bounce over 1 m,
wings within 10° of level, stopped on the runway, and the controller asking to disarm.
A go-around ordered on the approach climbs away and the aircraft lands on its second
approach.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from companion.control.mission.plan import checked_plan
from companion.messages import FlightMode, LandPhase
from ground.campaign.landing_score import LandingScore, landing_score_for_plan
from tests.support.closed_loop import ClosedLoop

PLAN = Path(__file__).resolve().parents[4] / "benchmarks" / "plans" / "land_east.plan"
CROSSWIND = (5.0, 0.0, 0.0)  # from the south, across the runway (which runs east)


def _low_on_approach(loop: ClosedLoop) -> bool:
    last = loop.samples[-1]
    return last.out.land_phase == LandPhase.APPROACH and last.alt_agl < 25.0


@pytest.mark.parametrize(
    ("airframe", "wind"),
    [("c172p", (0.0, 0.0, 0.0)), ("J3Cub", CROSSWIND)],
    ids=["c172p-calm", "J3Cub-crosswind"],
)
def test_the_landing_pattern_is_flown_to_a_stop_on_the_target(airframe: str, wind):  # type: ignore[no-untyped-def]
    items = checked_plan(PLAN)[0]
    loop = ClosedLoop(airframe, items, wind_ned=wind, turbulence="light" if any(wind) else "none")
    assert loop.fly_until_disarmed(600.0)
    score = landing_score_for_plan(loop.truth(), items)
    assert score.passed(), score


def test_a_steep_final_with_a_tailwind_is_flown_down_its_path_onto_the_target():
    """circuit_west's final from 100 m instead of 80 m (5.7°) with 5 m/s behind the aircraft
    needs more than 3 m/s of sink to follow: held to TECS_SINK_MAX's 3 m/s, the C172 stays
    metres above the path and lands hundreds of metres long; the airframe's TECS_APPR_SMAX
    lets it follow the path."""
    items = checked_plan(PLAN.with_name("circuit_west.plan"))[0]
    items[-2] = replace(items[-2], z=100.0)  # the final's first point, 80 m in the plan
    tailwind = (0.0, -5.0, 0.0)  # blowing west, along the westward final
    scores = []
    for smax in (0.0, 5.0):  # 0: TECS_SINK_MAX on the approach too
        loop = ClosedLoop("c172p", items, wind_ned=tailwind, turbulence="light",
                          range_max_m=12.0, overrides={"TECS_APPR_SMAX": smax})  # fmt: skip
        loop.fly_until_disarmed(700.0)
        scores.append(landing_score_for_plan(loop.truth(), items))
    held, free = scores
    assert free.passed(), free
    assert held.along_m > 20.0, held


def _gusty_landings(
    airframe: str, plan: Path, seed: int, without: dict[str, float]
) -> tuple[LandingScore, LandingScore]:
    """The plan flown in the crosswind and JSBSim's gust sequence ``seed``, once with the
    parameters ``without`` and once as the airframe ships: the two landings' scores."""
    items = checked_plan(plan)[0]
    scores = []
    for overrides in (without, {}):
        loop = ClosedLoop(airframe, items, wind_ned=CROSSWIND, turbulence="light",
                          range_max_m=12.0, overrides=overrides)  # fmt: skip
        loop.flight.fdm["atmosphere/randomseed"] = seed
        loop.fly_until_disarmed(600.0)
        scores.append(landing_score_for_plan(loop.truth(), items))
    return scores[0], scores[1]


def test_power_in_the_flare_holds_up_a_flare_begun_in_a_gusts_dive():
    """In JSBSim's own gust sequence (its seed 1, the one the simulated vehicle meets) the
    C172's flare on land_east begins in a gust's dive, nose 4° down and sinking 2 m/s, and
    its pitch lags the demand all the way down: at idle it touched down 26 m short (15 m
    since the flare pitches up from its least pitch when low and sinking too fast). Power
    against the sink that would land short of the point puts it on target."""
    idle, powered = _gusty_landings("c172p", PLAN, 1, {"LAND_FLARE_PWR": 0.0})
    assert powered.passed(), powered
    assert powered.along_m > idle.along_m + 10.0, (idle, powered)


def test_full_power_in_the_flare_holds_the_c172_up_through_a_lull():
    """In JSBSim's gust sequence 47 a lull meets the C172's flare in the crosswind: at
    TRIM_THROTTLE it sank 15.5 m short of the point (12.5 m since the flare pitches up from
    its least pitch when low and sinking too fast). With the airframe's LAND_FLARE_THR (full
    power, as a pilot gives in gusts) it touches down 6.5 m short."""
    items = checked_plan(PLAN)[0]
    scores = []
    for overrides in ({"LAND_FLARE_THR": 0.0}, {}):
        loop = ClosedLoop("c172p", items, FlightMode.LOITER, CROSSWIND, "light",
                          overrides=overrides, range_max_m=12.0)  # fmt: skip
        loop.flight.fdm["atmosphere/randomseed"] = 47
        loop.run(40.0)  # on the ground, idle
        loop.set_mode(FlightMode.MISSION)
        loop.fly_until_disarmed(640.0)
        scores.append(landing_score_for_plan(loop.truth(), items))
    trim, full = scores
    assert full.passed() and full.along_m > trim.along_m + 5.0, (trim, full)


def test_a_cub_fast_after_gusts_at_idle_flares_lower_and_lands_on_the_point():
    """In JSBSim's gust sequence 35 on circuit_east the Cub's final is flown 5-6 m/s fast at
    idle (rising air: its pitch holds the path). As the flare began its pitch went up to
    LAND_PITCH_CD, above the glide's, and at 28-30 m/s the wing lifted it off the path and
    held it there: it floated at 0.2-0.5 m/s of sink and touched down 48 m long. With the
    least pitch lowered by what the extra speed's lift makes up (LAND_FLARE_AOA) it lands
    on target."""
    circuit = PLAN.with_name("circuit_east.plan")
    floor, lowered = _gusty_landings("J3Cub", circuit, 35, {"LAND_FLARE_AOA": 0.0})
    assert floor.along_m > 40.0, floor
    assert lowered.passed(), lowered


@pytest.mark.parametrize(("airframe", "error_m"), [("J3Cub", -3.2), ("c172p", 3.2)])
def test_a_home_altitude_misread_at_arming_is_corrected_by_the_rangefinder(airframe, error_m):  # type: ignore[no-untyped-def]
    """The navigator's GPS-aided height read 3.2 m off when home was taken (as in a
    simulated Cub flight): the glide path lies 3.2 m off, and with the flare on the
    rangefinder alone the landing is 70-100 m off; a 12 m rangefinder that also finds the
    runway on the approach puts it on target."""
    items = checked_plan(PLAN)[0]
    blind = ClosedLoop(airframe, items, home_alt_error_m=error_m)
    blind.fly_until_disarmed(600.0)  # touched down far off the point (it may not stop to disarm)
    off = landing_score_for_plan(blind.truth(), items)
    loop = ClosedLoop(airframe, items, home_alt_error_m=error_m, range_max_m=12.0)
    assert loop.fly_until_disarmed(600.0)
    score = landing_score_for_plan(loop.truth(), items)
    assert score.passed(), score
    assert abs(off.along_m) > abs(score.along_m) + 50.0, (off, score)


def test_a_runway_a_metre_off_in_the_navigators_height_lands_where_the_true_one_does():
    """The simulated vehicle's navigator reads about 0.9 m low on the approach: the
    rangefinder moves the runway, and the glide path with it, in the last seconds before
    the flare. The controller follows the path's move as well as its slope, so the C172
    lands where it lands on the true height (1.8 m short); following the slope alone it
    ran above the moving path into the flare and landed 5.3-5.8 m short."""
    items = checked_plan(PLAN)[0]
    along = []
    for error_m in (0.0, 0.9, -0.9):
        loop = ClosedLoop("c172p", items, home_alt_error_m=error_m, range_max_m=12.0)
        assert loop.fly_until_disarmed(600.0)
        along.append(landing_score_for_plan(loop.truth(), items).along_m)
    assert abs(along[1] - along[0]) < 1.0 and abs(along[2] - along[0]) < 1.0, along


def test_a_go_around_on_the_approach_climbs_away_and_the_second_approach_lands():
    items = checked_plan(PLAN)[0]
    loop = ClosedLoop("c172p", items)
    loop.run(1.0)
    while loop.flight.t_s < 600.0 and not _low_on_approach(loop):
        loop.run(0.5)
    low = loop.samples[-1].alt_agl
    loop.status.go_arounds += 1  # the commander accepted MAV_CMD_DO_GO_AROUND
    loop.run(30.0)
    climbed = max(s.alt_agl for s in loop.samples[-1500:])
    assert climbed > low + 15.0
    assert loop.fly_until_disarmed(900.0)
    assert landing_score_for_plan(loop.truth(), items).passed()


def test_return_with_rtl_autoland_flies_the_missions_landing():
    items = checked_plan(PLAN)[0]
    loop = ClosedLoop("c172p", items, overrides={"RTL_AUTOLAND": 2.0})
    loop.run(60.0)  # airborne, on the first leg
    assert loop.samples[-1].alt_agl > 30.0
    loop.set_mode(FlightMode.RTL)
    assert loop.fly_until_disarmed(600.0)
    assert landing_score_for_plan(loop.truth(), items).passed()


def test_return_without_rtl_autoland_circles_home_and_does_not_land():
    items = checked_plan(PLAN)[0]
    loop = ClosedLoop("c172p", items)
    loop.run(60.0)
    loop.set_mode(FlightMode.RTL)
    assert not loop.fly_until_disarmed(400.0)
    assert min(s.alt_agl for s in loop.samples[-1000:]) > 50.0
