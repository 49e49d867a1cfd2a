"""The failsafe state machine judged by sensor time: no flapping, each change said once."""

from __future__ import annotations

import pytest

from companion.control.failsafe import FAILSAFE_PARAMS, Failsafes, Hysteresis, Situation
from companion.messages import FlightMode, NavFlags
from mavlink_dialect import companion as d

GOOD = int(NavFlags.POSITION_VALID | NavFlags.ATTITUDE_VALID)
DEAD = GOOD | int(NavFlags.DEAD_RECKONING)


def _failsafes(**overrides: float) -> Failsafes:
    params = {p.name: p.default for p in FAILSAFE_PARAMS}
    params.update(overrides)
    return Failsafes(params)


def _situation(t_us: int, flags: int, flying: bool = True) -> Situation:
    return Situation(
        now_us=t_us, mode=FlightMode.MISSION, flying=flying, gcs_silence_s=0.0,
        nav_flags=flags, fence_breach=None, nav_t_us=t_us,
    )  # fmt: skip


def _texts(fs: Failsafes, samples) -> list[str]:
    return [a.text for t, flags, flying in samples for a in fs.step(_situation(t, flags, flying))]


@pytest.mark.parametrize("rate_hz", [10, 25, 50, 100])
@pytest.mark.parametrize("pattern", [(True, False), (False, True), (True, True, False)])
def test_alternating_gps_flags_change_the_state_at_most_once_each_way_per_hold(rate_hz, pattern):
    lost_s, back_s = 1.0, 3.0
    hyst = Hysteresis(lost_s, back_s)
    period = round(1e6 / rate_hz)
    changes: list[tuple[int, bool]] = []
    for i in range(rate_hz * 120):
        change = hyst.update(i * period, pattern[i % len(pattern)])
        if change is not None:
            changes.append((i * period, change))
    # Good at least every third sample: the GPS never counts as lost at all.
    assert changes == []


@pytest.mark.parametrize("rate_hz", [10, 100])
def test_bursts_of_outage_and_fix_cannot_make_the_state_flap(rate_hz):
    # Outages just longer than the hold, fixes just shorter than the return hold: the GPS
    # goes lost once and stays lost (no return without a steady stretch of fixes).
    hyst = Hysteresis(1.0, 3.0)
    period = round(1e6 / rate_hz)
    changes, t = [], 0
    for _ in range(30):
        for good, seconds in ((False, 1.5), (True, 2.5)):
            for _ in range(round(seconds * rate_hz)):
                t += period
                if (c := hyst.update(t, good)) is not None:
                    changes.append((t, c))
    assert [c for _, c in changes] == [True]


def test_an_outage_is_announced_once_and_the_return_once_with_loiter():
    fs = _failsafes(FS_GPS_LOST_S=1.0, FS_GPS_BACK_S=3.0)
    period = 20_000  # 50 Hz navigation solutions
    samples = [(i * period, GOOD, True) for i in range(100)]  # 2 s good
    samples += [(i * period, DEAD, True) for i in range(100, 400)]  # 6 s dead reckoning
    samples += [(i * period, GOOD, True) for i in range(400, 800)]  # 8 s good
    actions = [a for t, flags, flying in samples for a in fs.step(_situation(t, flags, flying))]
    assert [a.text for a in actions] == [
        "Failsafe: GPS lost, holding heading and height",
        "GPS back: loitering here",
    ]
    assert actions[1].mode == FlightMode.LOITER


def test_a_transient_shorter_than_the_hold_does_not_undo_the_mission():
    fs = _failsafes(FS_GPS_LOST_S=1.0)
    period = 10_000
    samples = [(i * period, DEAD if 100 <= i < 180 else GOOD, True) for i in range(400)]
    assert _texts(fs, samples) == []


def test_a_navigator_restarted_in_flight_is_not_a_lost_gps_while_it_aligns():
    fs = _failsafes(FS_GPS_LOST_S=1.0)
    period = 20_000
    aligning = int(NavFlags.ALIGNING)
    samples = [(i * period, GOOD, True) for i in range(100)]
    samples += [(i * period, aligning, True) for i in range(100, 250)]  # 3 s re-aligning
    samples += [(i * period, GOOD, True) for i in range(250, 400)]
    assert _texts(fs, samples) == []
    stuck = [(i * period, aligning, True) for i in range(400, 1100)]  # 14 s: never aligns
    assert _texts(fs, stuck) == ["Failsafe: GPS lost, holding heading and height"]


def test_no_gps_failsafe_on_the_ground_or_in_the_take_off_roll():
    fs = _failsafes()
    period = 20_000
    samples = [(i * period, DEAD if i % 300 > 100 else GOOD, False) for i in range(3000)]
    assert _texts(fs, samples) == []


def test_late_and_repeated_samples_say_nothing_new():
    hyst = Hysteresis(1.0, 3.0)
    assert hyst.update(5_000_000, True) is None
    # An old sample arriving late, however bad, is ignored.
    assert hyst.update(1_000_000, False) is None
    assert hyst.update(5_000_000, False) is None
    assert hyst.update(5_500_000, False) is None
    assert hyst.update(6_000_000, False) is True


def _at(t_s: float, mode: FlightMode, breach: str | None = None, silence: float = 0.0):
    t_us = round(t_s * 1e6)
    return Situation(
        now_us=t_us, mode=mode, flying=True, gcs_silence_s=silence, nav_flags=GOOD,
        fence_breach=breach, nav_t_us=t_us,
    )  # fmt: skip


def _modes(fs: Failsafes, situations) -> list[FlightMode | None]:
    return [a.mode for s in situations for a in fs.step(s)]


def test_a_fence_breach_that_still_holds_takes_back_an_operators_mode_change():
    fs = _failsafes()
    first = _modes(fs, [_at(0.0, FlightMode.MISSION), _at(0.1, FlightMode.MISSION, "fence")])
    assert first == [FlightMode.RTL]
    # QGroundControl's one-click Start Mission while still outside: Return again at once.
    again = _modes(fs, [_at(0.2, FlightMode.RTL, "fence"), _at(0.3, FlightMode.MISSION, "fence")])
    assert again == [FlightMode.RTL]
    assert _modes(fs, [_at(0.4, FlightMode.GUIDED, "fence")]) == [FlightMode.RTL]
    # Taking Manual or Stabilized is taking control: the failsafe leaves it alone.
    assert _modes(fs, [_at(0.5, FlightMode.STABILIZED, "fence")]) == []
    assert _modes(fs, [_at(0.6, FlightMode.MANUAL, "fence")]) == []
    # Back inside: a mode change is the operator's.
    texts = [a.text for a in fs.step(_at(0.7, FlightMode.MANUAL))]
    assert texts == ["Back inside the fence"]
    assert _modes(fs, [_at(0.8, FlightMode.MISSION)]) == []


def test_a_lost_ground_station_still_silent_takes_back_a_mode_change():
    fs = _failsafes(FS_GCS_TIMEOUT=5.0)
    assert _modes(fs, [_at(0.0, FlightMode.MISSION, silence=6.0)]) == [FlightMode.RTL]
    assert _modes(fs, [_at(0.1, FlightMode.LOITER, silence=6.1)]) == [FlightMode.RTL]
    assert _modes(fs, [_at(0.2, FlightMode.RTL, silence=6.2)]) == []  # its own change
    assert _modes(fs, [_at(0.3, FlightMode.STABILIZED, silence=6.3)]) == []


def test_good_news_is_said_at_notice_and_bad_news_at_critical():
    """QGroundControl shows CRITICAL and worse as a "Vehicle Error" banner: a failsafe that
    acts is one; the link, GPS or fence coming back (and the mission resumed) is not."""
    fs = _failsafes(FS_GCS_TIMEOUT=5.0)
    (lost,) = fs.step(_at(0.0, FlightMode.MISSION, silence=6.0))
    assert lost.severity <= d.MAV_SEVERITY_CRITICAL
    (back,) = fs.step(_at(0.1, FlightMode.RTL, silence=0.5))
    assert back.text == "Ground station back: resuming the mission"
    assert back.mode == FlightMode.MISSION and back.severity == d.MAV_SEVERITY_NOTICE
    fence = _failsafes()
    fence.step(_at(0.0, FlightMode.MISSION, "fence"))
    (inside,) = fence.step(_at(0.1, FlightMode.RTL))
    assert inside.severity == d.MAV_SEVERITY_NOTICE


def test_a_return_the_operator_chose_while_the_link_was_lost_is_not_undone_when_it_returns():
    """Commanded over a second link or on the mode switch: the link's return keeps it."""
    fs = _failsafes(FS_GCS_TIMEOUT=5.0)
    assert _modes(fs, [_at(0.0, FlightMode.MISSION, silence=6.0)]) == [FlightMode.RTL]
    fs.operator_chose(FlightMode.RTL)
    (back,) = fs.step(_at(0.1, FlightMode.RTL, silence=0.5))
    assert back.mode is None and back.text == "Ground station back"


def test_a_mission_the_operator_chose_while_the_link_was_lost_resumes_when_it_returns():
    """Start Mission while still lost is taken back (Return again), and flown once the
    link returns, as it would have been had the operator not touched anything."""
    fs = _failsafes(FS_GCS_TIMEOUT=5.0)
    fs.step(_at(0.0, FlightMode.LOITER, silence=6.0))
    fs.operator_chose(FlightMode.MISSION)
    assert _modes(fs, [_at(0.1, FlightMode.MISSION, silence=6.1)]) == [FlightMode.RTL]
    (back,) = fs.step(_at(0.2, FlightMode.RTL, silence=0.5))
    assert back.mode == FlightMode.MISSION


def test_a_choice_made_before_the_link_was_lost_does_not_count():
    fs = _failsafes(FS_GCS_TIMEOUT=5.0)
    fs.operator_chose(FlightMode.RTL)  # the failsafe holds nothing yet
    fs.step(_at(0.0, FlightMode.MISSION, silence=6.0))
    (back,) = fs.step(_at(0.1, FlightMode.RTL, silence=0.5))
    assert back.mode == FlightMode.MISSION
