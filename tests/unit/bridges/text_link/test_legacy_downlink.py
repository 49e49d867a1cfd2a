"""The legacy text downlink's pacing: line capacity, rate checks, and a schedule that keeps
each kind near its rate, never puts frames on the wire faster than it carries them, skips
kinds without data and does not burst when they come back."""

from __future__ import annotations

import itertools

import pytest

from bridges.text_link.downlink import DownlinkSchedule, check_rates, frames_per_second

STEP_S = 0.001


def run(schedule, seconds, ready=lambda now: {"ATT", "POS"}, start_s=0.0, step_s=STEP_S):
    """Drive ``schedule`` in fixed steps; the (time, kind) of every frame sent."""
    sent = []
    for i in range(round(seconds / step_s)):
        now = start_s + i * step_s
        kind = schedule.due(now, ready(now))
        if kind is not None:
            schedule.sent(kind, now)
            sent.append((now, kind))
    return sent


def count(sent, kind):
    return sum(1 for _, k in sent if k == kind)


def closest_gap(sent):
    return min(b[0] - a[0] for a, b in itertools.pairwise(sent))


def wire_s(baud):
    return 25 * 10 / baud


# --- capacity and checks ---


def test_9600_baud_carries_38_4_frames_a_second():
    assert frames_per_second(9600) == 38.4
    assert frames_per_second(1200) == 4.8


def test_rates_beyond_the_line_are_refused_with_the_numbers():
    with pytest.raises(ValueError) as err:
        check_rates({"ATT": 30.0, "POS": 10.0}, 9600)
    text = str(err.value)
    for number in ("ATT 30 Hz", "POS 10 Hz", "40", "9600", "38.4"):
        assert number in text


def test_rates_within_the_line_are_accepted():
    check_rates({"ATT": 30.0, "POS": 8.0}, 9600)
    check_rates({"ATT": 0.0, "POS": 0.0}, 9600)


def test_negative_rates_and_a_baud_rate_of_zero_or_less_are_refused():
    with pytest.raises(ValueError, match="negative"):
        check_rates({"ATT": -1.0, "POS": 4.0}, 9600)
    for baud in (0, -9600):
        with pytest.raises(ValueError, match="baud"):
            check_rates({"ATT": 1.0}, baud)


def test_the_schedule_checks_its_rates():
    with pytest.raises(ValueError):
        DownlinkSchedule({"ATT": 30.0, "POS": 10.0}, 9600)


def test_a_rate_that_is_not_a_number_is_refused():
    with pytest.raises(ValueError):
        check_rates({"ATT": float("nan"), "POS": 4.0}, 9600)


# --- the schedule ---


@pytest.mark.parametrize(("att_hz", "pos_hz"), [(10.0, 4.0), (20.0, 5.0), (25.0, 10.0)])
def test_each_kind_goes_at_its_rate(att_hz, pos_hz):
    sent = run(DownlinkSchedule({"ATT": att_hz, "POS": pos_hz}, 9600), 10.0)
    assert abs(count(sent, "ATT") - att_hz * 10) <= 1
    assert abs(count(sent, "POS") - pos_hz * 10) <= 1


def test_near_capacity_no_two_frames_share_the_wire():
    sent = run(DownlinkSchedule({"ATT": 30.0, "POS": 8.0}, 9600), 10.0)
    assert closest_gap(sent) >= wire_s(9600) - 1e-9
    assert len(sent) <= 38.4 * 10 + 1


def test_near_capacity_a_prompt_caller_gets_the_full_rates():
    # A 1 ms loop wastes up to 1 ms of wire per frame (38 of 38.4 frames/s do not fit
    # then); polled every 0.2 ms the schedule delivers the rates asked for.
    sent = run(DownlinkSchedule({"ATT": 30.0, "POS": 8.0}, 9600), 10.0, step_s=0.0002)
    assert abs(count(sent, "ATT") - 300) <= 1
    assert abs(count(sent, "POS") - 80) <= 1
    assert closest_gap(sent) >= wire_s(9600) - 1e-9


def test_a_slow_line_is_never_asked_for_more_than_it_carries():
    sent = run(DownlinkSchedule({"ATT": 3.0, "POS": 1.5}, 1200), 10.0)
    assert closest_gap(sent) >= wire_s(1200) - 1e-9
    assert len(sent) <= 4.8 * 10 + 1
    assert abs(count(sent, "ATT") - 30) <= 1
    assert abs(count(sent, "POS") - 15) <= 1


def test_a_kind_without_data_is_never_chosen():
    schedule = DownlinkSchedule({"ATT": 10.0, "POS": 4.0}, 9600)
    sent = run(schedule, 5.0, ready=lambda now: {"ATT"})
    assert count(sent, "POS") == 0
    assert abs(count(sent, "ATT") - 50) <= 1
    assert schedule.due(5.0, set()) is None


def test_a_kind_whose_data_comes_back_does_not_burst():
    schedule = DownlinkSchedule({"ATT": 10.0, "POS": 4.0}, 9600)
    run(schedule, 2.0)  # both flowing
    run(schedule, 3.0, ready=lambda now: {"ATT"}, start_s=2.0)  # POS data stale
    back = run(schedule, 0.24, start_s=5.0)  # just under one POS period
    assert count(back, "POS") == 1
    later = run(schedule, 4.76, start_s=5.24)
    assert abs(count(later, "POS") - 4 * 4.76) <= 1


def test_a_kind_never_sent_goes_once_when_its_data_arrives():
    schedule = DownlinkSchedule({"ATT": 10.0, "POS": 4.0}, 9600)
    run(schedule, 2.0, ready=lambda now: {"ATT"})
    back = run(schedule, 0.24, start_s=2.0)
    assert count(back, "POS") == 1


def test_a_rate_of_zero_disables_a_kind():
    sent = run(DownlinkSchedule({"ATT": 0.0, "POS": 4.0}, 9600), 10.0)
    assert count(sent, "ATT") == 0
    assert abs(count(sent, "POS") - 40) <= 1


def test_nothing_goes_while_the_last_frame_is_on_the_wire():
    schedule = DownlinkSchedule({"ATT": 10.0, "POS": 4.0}, 9600)
    assert schedule.due(0.0, {"ATT", "POS"}) == "ATT"
    schedule.sent("ATT", 0.0)
    assert schedule.due(0.02, {"ATT", "POS"}) is None
    assert schedule.due(wire_s(9600), {"ATT", "POS"}) == "POS"


def test_a_caller_that_sleeps_wait_s_still_sends_every_kind():
    schedule = DownlinkSchedule({"ATT": 10.0, "POS": 4.0}, 9600)
    sent, now = [], 0.0
    while now < 10.0:
        kind = schedule.due(now, {"ATT", "POS"})
        if kind is not None:
            schedule.sent(kind, now)
            sent.append((now, kind))
        else:
            now += max(schedule.wait_s(now), 1e-6)
    assert abs(count(sent, "POS") - 40) <= 1
