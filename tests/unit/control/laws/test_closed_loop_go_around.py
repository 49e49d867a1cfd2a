"""A landing that goes around of itself, or flares on and keeps sinking, flown against
JSBSim on the true state: an approach a gust has left high at the flare, and a flare that
rising air holds up (below).

``benchmarks/plans/gusty_steep_final.plan`` is random plan 53 of
``benchmarks/varied_landings.py``: a Cub circles down from 85 m to a 848 m final across
a 5 m/s crosswind with light turbulence (JSBSim's gust sequence 55). A gust leaves it
3.2 m above the glide path where the flare is due. Flaring from there on the nominal
flare it touched down 19.8 m past the point (the issue's target: 15 m).
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

from companion.control.mission.plan import checked_plan
from companion.messages import LandPhase
from ground.campaign.landing_score import landing_score_for_plan
from mavlink_dialect import companion as d
from tests.support.closed_loop import ClosedLoop

PLANS = Path(__file__).resolve().parents[4] / "benchmarks" / "plans"


class Case(NamedTuple):
    """A plan flown by one airframe across its runway in light turbulence."""

    plan: Path
    airframe: str
    wind_ned: tuple[float, float, float]  # 5 m/s across the runway
    gusts: int  # JSBSim's turbulence seed
    longest_s: float


STEEP = Case(PLANS / "gusty_steep_final.plan", "J3Cub",
             (3.356723318148176, -3.705726455824863, 0.0), 55, 1500.0)  # fmt: skip


def _fly(overrides: dict[str, float], case: Case = STEEP) -> ClosedLoop:
    items = checked_plan(case.plan)[0]
    loop = ClosedLoop(case.airframe, items, wind_ned=case.wind_ned, turbulence="light",
                      overrides=overrides, range_max_m=12.0)  # fmt: skip
    loop.flight.fdm["atmosphere/randomseed"] = case.gusts
    assert loop.fly_until_disarmed(case.longest_s)
    return loop


def _went_around(loop: ClosedLoop) -> tuple[list[int], list[int]]:
    """The landing phase of every sample, and the samples where a go-around began."""
    phases = [s.out.land_phase for s in loop.samples]
    began = [k for k in range(1, len(phases)) if phases[k] == LandPhase.GO_AROUND
             and phases[k - 1] != LandPhase.GO_AROUND]  # fmt: skip
    return phases, began


def test_an_approach_left_high_by_a_gust_goes_around_and_lands_on_target_the_second_time():
    items = checked_plan(STEEP.plan)[0]
    loop = _fly({})
    phases, went_around = _went_around(loop)
    assert len(went_around) == 1
    # From the flare's height, never on the wheels, then round to the approach again.
    k = went_around[0]
    assert not any(s.on_wheels for s in loop.samples[k - 500 : k + 500])  # 10 s about it
    assert LandPhase.FLARE in phases[went_around[0] :]
    texts = [t for sev, t in loop.controller.lander.said if "going around" in t]
    assert texts == [texts[0]] and texts[0].startswith("Land: 3.")
    assert texts[0].endswith("going around 1/2") and len(texts[0]) <= 50
    assert (d.MAV_SEVERITY_WARNING, texts[0]) in loop.controller.lander.said
    score = landing_score_for_plan(loop.truth(), items)
    assert score.passed(), score
    # Flared from up there instead (LAND_GA_HGT 0: off) on the nominal flare alone
    # (LAND_FLOAT_SINK 0), it touches down too far along.
    stayed = _fly({"LAND_GA_HGT": 0.0, "LAND_FLOAT_SINK": 0.0})
    floated = landing_score_for_plan(stayed.truth(), items)
    assert floated.along_m > 15.0, floated


def test_flared_from_high_a_flare_that_would_float_long_keeps_sinking_onto_the_target():
    """Without the go-around the flare begins 3.2 m above the path. Its nominal shape
    would float far past the point, so its sink demand stays at up to LAND_FLOAT_SINK
    (1.2 m/s) until the flare that touches down near the point asks less: on target,
    firmly but under the issue's 1.5 m/s."""
    items = checked_plan(STEEP.plan)[0]
    loop = _fly({"LAND_GA_HGT": 0.0})
    assert LandPhase.GO_AROUND not in {s.out.land_phase for s in loop.samples}
    score = landing_score_for_plan(loop.truth(), items)
    assert score.passed() and abs(score.along_m) < 10.0, score
    assert 0.6 < score.sink_m_s <= 1.5, score  # firmer than the Cub's nominal 0.5 m/s


def test_with_no_go_arounds_left_the_landing_flares_from_where_it_is():
    loop = _fly({"LAND_GA_MAX": 0.0})
    assert LandPhase.GO_AROUND not in {s.out.land_phase for s in loop.samples}
    assert not [t for _, t in loop.controller.lander.said if "going around" in t]


# Random jump plan 22 of benchmarks/jump_landings.py (take-off, a loop flown twice, a
# landing on a 345° runway) with JSBSim's gust sequence 24 across it: the C172 flares from
# 5 m, 125 m before the point, and rising air holds it at 4 m for the next 50 m, its least
# pitch (LAND_PITCH_CD 0°) 2-3° above its glide's. It touched down 41.8 m long.
BALLOON = Case(PLANS / "jump_balloon.plan", "c172p",
               (1.29785625847449, 4.828619795794508, 0.0), 24, 2000.0)  # fmt: skip


def test_a_flare_held_up_by_rising_air_goes_around_and_lands_on_target_the_second_time():
    items = checked_plan(BALLOON.plan)[0]
    loop = _fly({}, BALLOON)
    phases, went_around = _went_around(loop)
    assert len(went_around) == 1
    k = went_around[0]
    assert phases[k - 1] == LandPhase.FLARE  # from the flare itself, in the air
    assert not any(s.on_wheels for s in loop.samples[k - 500 : k + 500])
    texts = [t for sev, t in loop.controller.lander.said if "going around" in t]
    assert len(texts) == 1 and texts[0].startswith("Land: would land ")
    assert texts[0].endswith("m long: going around 1/2") and len(texts[0]) <= 50
    score = landing_score_for_plan(loop.truth(), items)
    assert score.passed(), score
    # Flared on (LAND_GA_LONG 0: off), it touches down far past the point.
    stayed = landing_score_for_plan(_fly({"LAND_GA_LONG": 0.0}, BALLOON).truth(), items)
    assert stayed.along_m > 30.0, stayed
