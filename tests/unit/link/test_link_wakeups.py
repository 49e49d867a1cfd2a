"""The link sleeps through the navigation states no stream is waiting for, and still sends
every stream on the same states at the same times."""

from __future__ import annotations

import pytest

from companion.link.codec import dialect as d
from companion.link.codec import new_encoder
from companion.link.endpoints import open_endpoint
from companion.link.link_router import LinkRouter
from companion.link.stream_schedule import BATCH_S

ATTITUDE = d.MAVLINK_MSG_ID_ATTITUDE
MAX_WAIT_S = 0.05  # the link plug-in's


@pytest.fixture
def endpoint():
    endpoint = open_endpoint("udpout://127.0.0.1:9")  # nothing is sent here
    yield endpoint
    endpoint.close()


def fly(router: LinkRouter, gated: bool, nav_hz: int, seconds: float = 10.0):
    """A link woken as ``next_wake`` says (or by every state when not ``gated``), states
    at ``nav_hz`` out of phase with the streams' grid; returns (what was due at which
    millisecond, with the age of the state it carries) and the number of wake-ups."""
    period_ms, sent, wakes = 1000 // nav_hz, [], 0
    nav_at, state_at, wake_at, nav_wanted = float("-inf"), float("-inf"), 0.0, True
    for ms in range(int(seconds * 1000)):
        now = ms / 1000
        state = ms % period_ms == 7
        if state:
            state_at = now
        if not ((state and (nav_wanted or not gated)) or now >= wake_at - 1e-9):
            continue
        wakes += 1
        if state:
            nav_at = now
        due = router.schedules[0].due(now, nav_at)
        sent += [(ms, msg_id, round(now - state_at, 6)) for msg_id in due]
        timeout, nav_wanted = router.next_wake(now, MAX_WAIT_S)
        wake_at = now + timeout
    return sent, wakes


@pytest.mark.parametrize("attitude_hz", [10, 50])
def test_streams_go_out_on_the_same_states_with_fewer_wakeups(endpoint, attitude_hz):
    runs = []
    for gated in (False, True):
        router = LinkRouter(new_encoder(1, 1), [endpoint], [], None)
        router.schedules[0].set_interval(ATTITUDE, 1e6 / attitude_hz)
        runs.append(fly(router, gated, nav_hz=50))
    (every_state, woken_always), (gated_sent, woken_gated) = runs
    assert gated_sent == every_state
    attitude = [age for _, msg_id, age in gated_sent if msg_id == ATTITUDE]
    assert abs(len(attitude) - 10 * attitude_hz) <= 1
    assert max(attitude[1:]) == 0.0  # each on the state that woke the link
    if attitude_hz == 10:  # fifty states a second, ten wanted
        assert woken_gated < 0.6 * woken_always


def test_an_endpoint_nobody_has_spoken_to_neither_spins_the_link_nor_wakes_it_on_states():
    waiting = open_endpoint("udpin://127.0.0.1:0")  # no ground station has spoken yet
    try:
        router = LinkRouter(new_encoder(1, 1), [waiting], [], None)
        assert router.next_wake(5.0, MAX_WAIT_S) == (MAX_WAIT_S, False)
    finally:
        waiting.close()


def test_before_the_first_state_the_streams_that_carry_one_wake_nobody(endpoint):
    """A vehicle on the bench with its sensors silent: ATTITUDE and the other streams of
    the navigation state have nothing to send, so only the other streams' timers (2 Hz
    at most) wake the link, and the first state ends any sleep."""
    counts = {}
    for nav_known in (True, False):
        router = LinkRouter(new_encoder(1, 1), [endpoint], [], None)
        now, wakes = 0.0, 0
        while now < 10.0:
            router.schedules[0].due(now)
            timeout, nav_wanted = router.next_wake(now, 1.0, nav_known)
            assert nav_wanted or nav_known
            now, wakes = now + max(timeout, 1e-3), wakes + 1
        counts[nav_known] = wakes / 10.0
    assert counts[False] <= 3.0 < 10.0 <= counts[True]


def test_slower_streams_ride_the_wakeups_of_the_fastest_at_their_own_rates(endpoint):
    """At the default rates (ATTITUDE 10 Hz, the others 5 Hz to 0.2 Hz) a link that sends
    what falls due within BATCH_S with what it woke for is no longer woken apart for the
    slower streams, and every stream keeps its rate."""
    wakes_by_batch, counts_by_batch = {}, {}
    for early_s in (0.0, BATCH_S):
        router = LinkRouter(new_encoder(1, 1), [endpoint], [], None)
        schedule, counts = router.schedules[0], {}
        nav_at, nav_wanted, wake_at, wakes = float("-inf"), True, 0.0, 0
        for ms in range(20_000):
            now = ms / 1000
            state = ms % 20 == 7  # the navigator at 50 Hz, out of phase with the grid
            if not ((state and nav_wanted) or now >= wake_at - 1e-9):
                continue
            wakes, nav_at = wakes + 1, now if state else nav_at
            # Served late, as a busy link is: the streams drift apart without the batch.
            for msg_id in schedule.due(now + 0.003 * (ms % 3), nav_at, early_s):
                counts[msg_id] = counts.get(msg_id, 0) + 1
            timeout, nav_wanted = router.next_wake(now, 1.0)
            wake_at = now + max(timeout, 1e-3)
        wakes_by_batch[early_s], counts_by_batch[early_s] = wakes / 20.0, counts
    for msg_id, period in router.schedules[0].period_s.items():
        if period > 0:
            assert abs(counts_by_batch[BATCH_S][msg_id] - 20.0 / period) <= 1.5, msg_id
    # Two wake-ups per ATTITUDE (its time opens the gate, the next state sends it), the
    # others riding them: 25.1 a second without the batch, 21.95 with it.
    assert wakes_by_batch[BATCH_S] <= min(22.5, wakes_by_batch[0.0] - 2.0)


def test_link_status_rides_the_wakeups_of_attitude_at_its_own_rate():
    """Once a ground station is heard, link/status (5 Hz) goes out on the link's ATTITUDE
    wake-ups (10 Hz, out of phase with it) up to STATUS_EARLY_S ahead of its time, so its
    own timer no longer wakes the link; alone, its timer wakes the link at its rate."""
    from companion.link.gcs_watch import STATUS_PERIOD_S, GcsWatch

    gcs = GcsWatch()
    gcs.last_heard_s = 0.0
    sent, timer_wakes, now, attitude_at = [], 0, 0.0, 0.037
    while now < 20.0:
        if gcs.status_due(now):
            sent.append(now)
        if gcs.next_due() < attitude_at:  # its timer ends the sleep first
            now, timer_wakes = gcs.next_due(), timer_wakes + 1
        else:
            now, attitude_at = attitude_at, attitude_at + 0.1
    assert timer_wakes == 0
    assert abs(len(sent) - 20.0 / STATUS_PERIOD_S) <= 1
    alone = GcsWatch()
    alone.last_heard_s, now, count = 0.0, 0.0, 0
    for _ in range(100):  # woken by its own timer only
        count += alone.status_due(now)
        now = alone.next_due()
    assert count == 100 and abs(now - 100 * STATUS_PERIOD_S) < STATUS_PERIOD_S
