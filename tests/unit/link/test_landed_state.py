"""EXTENDED_SYS_STATE's landed state from the flight controller's status.

QGroundControl shows its "Land Abort" action for a fixed wing only while the landed state
is LANDING, and counts TAKEOFF and LANDING as flying (Vehicle::_handleExtendedSysState).
"""

from __future__ import annotations

import pytest
from pymavlink.dialects.v20 import common as m

from companion.link.flight_messages import landed_state
from companion.messages import ControlStatus, LandPhase, TakeoffPhase


def test_no_controller_no_landed_state():
    assert landed_state(None) is None


@pytest.mark.parametrize(
    "phase", [TakeoffPhase.GROUND_ROLL, TakeoffPhase.ROTATE, TakeoffPhase.CLIMB_OUT]
)
def test_the_whole_take_off_is_takeoff(phase):
    on_the_roll = ControlStatus(landed=int(phase == TakeoffPhase.GROUND_ROLL), takeoff_phase=phase)
    assert landed_state(on_the_roll) == m.MAV_LANDED_STATE_TAKEOFF


def test_an_aborted_take_off_is_on_the_ground():
    """TKOFF_TIMEOUT: the roll never got going; QGroundControl must not count it flying."""
    aborted = ControlStatus(landed=1, takeoff_phase=TakeoffPhase.ABORTED)
    assert landed_state(aborted) == m.MAV_LANDED_STATE_ON_GROUND


@pytest.mark.parametrize(
    ("phase", "landed", "state"),
    [
        (LandPhase.APPROACH, 0, m.MAV_LANDED_STATE_LANDING),
        (LandPhase.FLARE, 0, m.MAV_LANDED_STATE_LANDING),
        (LandPhase.ROLLOUT, 0, m.MAV_LANDED_STATE_LANDING),
        (LandPhase.ROLLOUT, 1, m.MAV_LANDED_STATE_LANDING),  # slowing down on the runway
        (LandPhase.STOPPED, 1, m.MAV_LANDED_STATE_ON_GROUND),
        (LandPhase.GO_AROUND, 0, m.MAV_LANDED_STATE_IN_AIR),  # climbing away: not landing
    ],
)
def test_landing_from_the_approach_to_the_stop(phase, landed, state):
    assert landed_state(ControlStatus(landed=landed, land_phase=phase)) == state


def test_otherwise_on_the_ground_or_in_the_air():
    assert landed_state(ControlStatus(landed=1)) == m.MAV_LANDED_STATE_ON_GROUND
    assert landed_state(ControlStatus(landed=0)) == m.MAV_LANDED_STATE_IN_AIR
