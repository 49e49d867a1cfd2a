"""The HEARTBEAT timer: 1 Hz on its phase, and one heartbeat (never a burst) when late."""

from __future__ import annotations

import itertools

from companion.link.codec import dialect as d
from companion.link.codec import new_encoder
from companion.link.identity import IdentityService


def beats(identity: IdentityService, times: list[float]) -> list[float]:
    return [t for t in times if identity.tick(t)]


def test_the_first_heartbeat_goes_at_once_and_alone():
    identity = IdentityService(new_encoder(1, 1), 1, d.MAV_AUTOPILOT_GENERIC, 0)
    # A link starts long after the monotonic clock's zero, and steps every 10 ms.
    start = 5000.0
    sent = beats(identity, [start + 0.01 * i for i in range(301)])
    assert sent[0] == start
    assert len(sent) == 4  # 0, 1, 2 and 3 s
    gaps = [b - a for a, b in itertools.pairwise(sent)]
    assert all(abs(g - 1.0) < 0.011 for g in gaps), gaps


def test_after_a_stall_one_heartbeat_then_the_rate_again():
    identity = IdentityService(new_encoder(1, 1), 1, d.MAV_AUTOPILOT_GENERIC, 0)
    assert beats(identity, [100.0, 100.5, 101.0]) == [100.0, 101.0]
    # The link was held 3.2 s (a busy machine): one heartbeat at once, not four.
    steps = [104.2 + 0.01 * i for i in range(210)]
    sent = beats(identity, steps)
    assert sent[0] == 104.2 and len(sent) == 3  # 104.2, 105.2, 106.2
    assert abs(sent[1] - 105.2) < 0.011 and abs(sent[2] - 106.2) < 0.011


def test_a_slightly_late_step_keeps_the_phase():
    identity = IdentityService(new_encoder(1, 1), 1, d.MAV_AUTOPILOT_GENERIC, 0)
    sent = beats(identity, [10.0, 11.3, 12.0, 12.9, 13.0])
    assert sent == [10.0, 11.3, 12.0, 13.0]  # 11.3 was late; 12.0 is due on the phase
