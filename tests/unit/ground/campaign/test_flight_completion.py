"""When a campaign flight's mission counts as done, read off MISSION_CURRENT."""

from __future__ import annotations

from pathlib import Path

from ground.campaign.flight_run import Timeline, _Pilot, endless_final_item
from mavlink_dialect import companion as d

PLANS = Path(__file__).resolve().parents[4] / "qgc_plans"


def _current(seq: int, state: int) -> d.MAVLink_mission_current_message:
    return d.MAVLink_mission_current_message(seq, 6, state, 0)


def _pilot(plan: Path) -> _Pilot:
    pilot = _Pilot(None, None, 0.0, Timeline(), 5.0)  # type: ignore[arg-type]
    pilot.endless_seq = endless_final_item(plan)
    return pilot


def test_a_plan_ending_in_an_unlimited_loiter_is_done_once_that_loiter_is_current() -> None:
    pilot = _pilot(PLANS / "loiter.plan")
    assert pilot.endless_seq == 5
    assert not pilot._complete(_current(4, d.MISSION_STATE_ACTIVE))
    assert not pilot.tl.completed
    assert pilot._complete(_current(5, d.MISSION_STATE_ACTIVE))
    assert pilot.tl.completed
    assert pilot.tl.seqs == [4, 5]


def test_a_plan_that_ends_is_done_only_when_the_vehicle_says_complete() -> None:
    pilot = _pilot(PLANS / "square.plan")
    assert pilot.endless_seq is None
    last = 5
    assert not pilot._complete(_current(last, d.MISSION_STATE_ACTIVE))
    assert pilot._complete(_current(last, d.MISSION_STATE_COMPLETE))
    assert pilot.tl.completed
