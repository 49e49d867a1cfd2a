"""The heartbeat of a link started beside a commander: silent until the commander's status
is read (a link restarted in flight must not say Hold, nor disarmed), then its mode."""

from __future__ import annotations

from typing import Any

from companion.control.modes import BY_MODE, INITIAL_MODE
from companion.link.codec import dialect as d
from companion.link.codec import new_encoder
from companion.link.heartbeat_state import COMMANDER_WAIT_S, HeartbeatFollower
from companion.link.identity import IdentityService
from companion.messages import FlightMode, SystemHealth, VehicleStatus

START = 7000.0  # the monotonic clock when the link started


def _link(commander: bool) -> tuple[IdentityService, HeartbeatFollower]:
    identity = IdentityService(new_encoder(1, 1), 1, d.MAV_AUTOPILOT_PX4, 0)
    return identity, HeartbeatFollower(identity.state, commander, START)


def _status(mode: FlightMode, armed: bool) -> VehicleStatus:
    return VehicleStatus(t_us=1, mode=int(mode), armed=int(armed))


def _beat(identity: IdentityService, now_s: float) -> Any:
    out = identity.tick(now_s)
    return out[0].msg if out else None


def test_a_restarted_link_says_nothing_until_the_commander_then_its_mode_and_arming():
    identity, follower = _link(commander=True)
    for t in (START, START + 0.1, START + 0.2):  # the status not read yet
        follower.update(None, None, t)
        assert _beat(identity, t) is None
    assert identity.next_due() == float("inf")  # the link sleeps on the bus, not a timer
    changed = follower.update(_status(FlightMode.MISSION, armed=True), None, START + 0.3)
    beat = _beat(identity, START + 0.3)
    assert changed  # CURRENT_MODE goes out at once too
    assert beat.custom_mode == BY_MODE[FlightMode.MISSION].px4
    assert beat.base_mode & d.MAV_MODE_FLAG_SAFETY_ARMED  # armed before the health table
    assert beat.system_status == d.MAV_STATE_ACTIVE


def test_the_health_table_has_the_last_word_on_arming():
    identity, follower = _link(commander=True)
    follower.update(_status(FlightMode.MISSION, armed=True), SystemHealth(flight_running=0), START)
    assert not _beat(identity, START).base_mode & d.MAV_MODE_FLAG_SAFETY_ARMED


def test_a_silent_commander_gets_heartbeats_with_no_known_mode_after_the_wait():
    identity, follower = _link(commander=True)
    follower.update(None, None, START + COMMANDER_WAIT_S - 0.1)
    assert _beat(identity, START + COMMANDER_WAIT_S - 0.1) is None
    follower.update(None, None, START + COMMANDER_WAIT_S)
    beat = _beat(identity, START + COMMANDER_WAIT_S)
    assert beat.custom_mode == 0  # "Unknown", never a mode the vehicle may not be in


def test_without_a_commander_the_first_heartbeat_names_the_initial_mode():
    identity, follower = _link(commander=False)
    assert follower.assumed == INITIAL_MODE
    follower.update(None, None, START)
    assert _beat(identity, START).custom_mode == BY_MODE[INITIAL_MODE].px4
