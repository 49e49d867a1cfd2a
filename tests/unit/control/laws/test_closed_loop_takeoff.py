"""Runway take-offs flown by the control laws against JSBSim on the true state.

The aircraft starts on the runway facing east and takes off towards a point 2 km ahead,
in a 5 m/s wind with light turbulence from behind on either side: the hardest quarter
for a tail dragger, which swings its nose round the main wheels once its tail is up.
It must leave the ground, keep near the centreline while on it and climb away.
"""

from __future__ import annotations

import math

import pytest

from bridges.jsbsim.fdm import Home
from companion.control.mission.items import MissionItem
from companion.geodesy import LocalFrame
from companion.messages import TakeoffPhase
from mavlink_dialect import companion as d
from tests.support.closed_loop import ClosedLoop

WIND_M_S = 5.0
CLIMBED_AGL_M = 40.0


def _takeoff_item() -> MissionItem:
    home = Home()
    lat, lon = LocalFrame(home.lat_deg, home.lon_deg).latlon(0.0, 2000.0)
    return MissionItem(
        seq=0, command=d.MAV_CMD_NAV_TAKEOFF, frame=d.MAV_FRAME_GLOBAL_RELATIVE_ALT,
        current=0, autocontinue=1, param1=15.0, param2=0.0, param3=0.0, param4=0.0,
        x=round(lat * 1e7), y=round(lon * 1e7), z=100.0,
    )  # fmt: skip


@pytest.mark.parametrize("towards_deg", [45, 135], ids=["from_right_rear", "from_left_rear"])
def test_the_cub_takes_off_with_a_quartering_tailwind(towards_deg: int) -> None:
    rad = math.radians(towards_deg)
    wind = (WIND_M_S * math.cos(rad), WIND_M_S * math.sin(rad), 0.0)
    loop = ClosedLoop("J3Cub", [_takeoff_item()], wind_ned=wind, turbulence="light")
    loop.flight.fdm["atmosphere/randomseed"] = 3
    loop.run(60.0)
    rolling = [s for s in loop.samples if s.out.takeoff_phase == TakeoffPhase.GROUND_ROLL]
    assert rolling, "no ground roll"
    # On the wheels the heading stays near the runway's (east): a ground loop swung it ±30°.
    worst = max(abs(math.degrees(s.yaw) - 90.0) for s in rolling)
    assert worst < 15.0, f"the nose swung {worst:.0f}° off the runway heading on the ground"
    top = max(s.alt_agl for s in loop.samples)
    assert top > CLIMBED_AGL_M, f"climbed to {top:.1f} m above the runway in 60 s"


def _brakes_stuck(loop: ClosedLoop) -> None:
    """Wheel brakes held on whatever the controller commands (a dragging brake)."""
    set_controls = loop.flight.set_controls

    def held(controls: dict[str, float]) -> None:
        set_controls(controls)
        loop.flight.fdm["fcs/left-brake-cmd-norm"] = 1.0
        loop.flight.fdm["fcs/right-brake-cmd-norm"] = 1.0

    loop.flight.set_controls = held  # type: ignore[method-assign]


def test_a_roll_that_never_gets_going_is_aborted_at_tkoff_timeout() -> None:
    """ArduPlane's TKOFF_TIMEOUT: not at 4 m/s after that long, idle, brakes, disarm, said."""
    loop = ClosedLoop("c172p", [_takeoff_item()], overrides={"TKOFF_TIMEOUT": 8.0})
    _brakes_stuck(loop)
    assert loop.fly_until_disarmed(30.0)
    aborted = [s for s in loop.samples if s.out.takeoff_phase == TakeoffPhase.ABORTED]
    assert 8.0 < aborted[0].t_s < 8.2  # the first step past the limit
    assert all(s.out.throttle == 0.0 and s.out.disarm for s in aborted)
    assert max(s.out.throttle for s in loop.samples) == 1.0  # it had tried at full power
    said = loop.controller.lander.said
    assert said and said[0][1].startswith("Takeoff aborted: 0.") and len(said) == 1


def test_a_roll_that_gets_going_is_not_aborted() -> None:
    """The same limit on a free roll: past 4 m/s in time, the climb goes on after it."""
    loop = ClosedLoop("c172p", [_takeoff_item()], overrides={"TKOFF_TIMEOUT": 8.0})
    loop.run(40.0)
    aborted = TakeoffPhase.ABORTED
    assert not any(s.out.takeoff_phase == aborted or s.out.disarm for s in loop.samples)
    assert max(s.alt_agl for s in loop.samples) > CLIMBED_AGL_M
