"""Telemetry that carries the navigation state goes out on a fresh state, at its rate."""

from __future__ import annotations

from itertools import pairwise

from companion.link.codec import dialect as d
from companion.link.stream_schedule import FOLLOWS_NAV, NAV_HOLD_S, StreamSchedule

ATTITUDE = d.MAVLINK_MSG_ID_ATTITUDE
SYS_STATUS = d.MAVLINK_MSG_ID_SYS_STATUS
NAV_PERIOD_MS = 20


def fly(schedule: StreamSchedule, seconds: float, nav_phase_ms: int) -> list[tuple[float, float]]:
    """Step a link every millisecond with states every 20 ms; (sent at, state age) of ATTITUDE."""
    sent, nav_at = [], float("-inf")
    for ms in range(int(seconds * 1000)):
        now = ms / 1000
        if ms >= nav_phase_ms and (ms - nav_phase_ms) % NAV_PERIOD_MS == 0:
            nav_at = now
        if ATTITUDE in schedule.due(now, nav_at):
            sent.append((now, now - nav_at))
    return sent


def test_attitude_is_sent_on_a_fresh_state_at_its_rate():
    schedule = StreamSchedule()
    assert schedule.set_interval(ATTITUDE, 100_000)  # 10 Hz, as QGroundControl asks
    sent = fly(schedule, 10.0, nav_phase_ms=13)  # states out of phase with the 10 Hz grid
    assert 99 <= len(sent) <= 101
    assert max(age for _, age in sent[1:]) < 1e-9  # never a state from an earlier period


def test_attitude_keeps_its_rate_when_the_navigator_is_silent():
    schedule = StreamSchedule()
    schedule.set_interval(ATTITUDE, 100_000)
    times = [ms / 1000 for ms in range(5000) if ATTITUDE in schedule.due(ms / 1000)]
    assert 49 <= len(times) <= 51
    gaps = [b - a for a, b in pairwise(times)]
    assert max(gaps) < 0.1 + NAV_HOLD_S
    assert schedule.next_time() <= times[-1] + 0.1 + NAV_HOLD_S


def test_streams_that_do_not_carry_the_state_keep_their_timer():
    schedule = StreamSchedule()
    times = [ms / 1000 for ms in range(3000) if SYS_STATUS in schedule.due(ms / 1000, -1.0)]
    assert times == [0.0, 1.0, 2.0]


def test_a_rate_above_the_navigators_is_kept():
    # 50 Hz asked for, states at 20 Hz: every 20 ms all the same, some states sent twice.
    schedule = StreamSchedule()
    schedule.set_interval(ATTITUDE, 20_000)
    nav_at, sent = float("-inf"), []
    for ms in range(5000):
        if ms % 50 == 0:
            nav_at = ms / 1000
        if ATTITUDE in schedule.due(ms / 1000, nav_at):
            sent.append(ms)
    gaps = sorted(b - a for a, b in pairwise(sent))
    assert 245 <= len(sent) <= 255
    assert 15 <= gaps[len(gaps) // 2] <= 25


def test_the_state_goes_first_and_a_skipped_stream_before_it():
    # One wake-up with ATTITUDE and the slower streams riding it: the streams carrying the
    # state are framed first, though sent most recently (each stream had its last turn).
    schedule = StreamSchedule()
    for mid, period in schedule.period_s.items():
        schedule.mark_sent(mid, 1.0 - period)
    schedule.next_due = dict.fromkeys(schedule.next_due, 1.0)
    due = schedule.due(1.0, nav_at_s=1.0)
    carrying = [mid for mid in due if mid in FOLLOWS_NAV]
    assert due[: len(carrying)] == carrying and ATTITUDE in carrying and SYS_STATUS in due
    # SYS_STATUS's turn at 1.0 was skipped (out of budget, never marked sent): at its next
    # turn it goes before the state, so a fast stream cannot starve it.
    for mid, period in schedule.period_s.items():
        if mid != SYS_STATUS:
            schedule.mark_sent(mid, 2.0 - period)  # the others had their turns since
    schedule.next_due = dict.fromkeys(schedule.next_due, 2.0)
    due = schedule.due(2.0, nav_at_s=2.0)
    assert due.index(SYS_STATUS) < due.index(ATTITUDE)


def test_the_next_wake_follows_every_send_and_every_rate_asked():
    """The link sleeps until ``next_time``/``nav_due``: each answer must move with a sent
    stream and a new rate, or the link would oversleep a stream (or wake for nothing)."""
    schedule = StreamSchedule()
    for msg_id in schedule.period_s:
        schedule.set_interval(msg_id, -1)  # all off ...
    assert schedule.next_time() == float("inf") and schedule.nav_due() == float("inf")
    schedule.set_interval(SYS_STATUS, 1_000_000)  # ... but SYS_STATUS at 1 Hz
    assert schedule.next_time() == 0.0
    assert schedule.due(0.0) == [SYS_STATUS]
    assert schedule.next_time() == 1.0  # sent: the next is a period on
    schedule.set_interval(ATTITUDE, 100_000)  # ATTITUDE asked for: due at once
    assert schedule.nav_due() == 0.0 and schedule.next_time() == NAV_HOLD_S
    assert schedule.due(0.01, nav_at_s=0.01) == [ATTITUDE]
    assert schedule.nav_due() == 0.1 and schedule.next_time() == 0.1 + NAV_HOLD_S
    schedule.set_interval(ATTITUDE, -1)  # turned off again
    assert schedule.nav_due() == float("inf") and schedule.next_time() == 1.0
