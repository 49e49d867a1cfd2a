"""Armed on the ground: which mode commands the commander refuses, and what the operator
is told on arming or entering a mode (issue 47.1: never armed and silent)."""

from __future__ import annotations

import math

from companion.control.commander import Commander
from companion.control.ground_rules import first_to_fly, ground_notice, standing
from companion.messages import CommandId, CommandResult, FlightMode, NavFlags, NavState
from companion.messages import VehicleCommand as Cmd
from mavlink_dialect import companion as d
from tests.unit.control.mission.executor_flying import item, speed, wp

HERE = (-37.9105, 145.1340, 80.0)


def _commander() -> Commander:
    c = Commander(lambda: 3)
    nav = NavState(flags=int(NavFlags.POSITION_VALID))
    nav.lat_deg, nav.lon_deg, nav.alt_msl_m = HERE
    assert c.on_nav(nav)
    return c


def _asks(c: Commander, command: CommandId, *params: float) -> tuple[CommandResult, str]:
    values = [*params, *([math.nan] * 7)][:7]
    cmd = Cmd(command=int(command))
    cmd.param[:] = values
    decision = c.handle(cmd)
    assert decision is not None
    return decision.result, decision.reason


AIRBORNE_ONLY = [
    (CommandId.SET_MODE, (float(FlightMode.LOITER),), "Hold"),
    (CommandId.SET_MODE, (float(FlightMode.RTL),), "Return"),
    (CommandId.RETURN_TO_LAUNCH, (), "Return"),
    (CommandId.REPOSITION, (HERE[0] + 0.01, HERE[1], 200.0), "Guided"),
    (CommandId.LOITER, (HERE[0], HERE[1], 200.0), "Hold"),
    (CommandId.ORBIT, (HERE[0], HERE[1], 200.0, 200.0), "Hold"),
]


def test_armed_on_the_ground_modes_that_cannot_fly_from_there_are_refused_with_the_reason():
    c = _commander()
    c.armed, c.landed = True, True
    before = c.status(0).changes
    for command, params, name in AIRBORNE_ONLY:
        result, reason = _asks(c, command, *params)
        assert result == CommandResult.DENIED, command
        assert reason == f"{name}: on the ground, take off first"
    assert c.mode == FlightMode.LOITER and c.status(0).changes == before  # nothing changed
    # What can fly from the runway is accepted: Mission and Takeoff.
    assert _asks(c, CommandId.MISSION_START, 0, 0)[0] == CommandResult.ACCEPTED
    assert _asks(c, CommandId.TAKEOFF, 0, 0, 200.0)[0] == CommandResult.ACCEPTED
    assert c.mode == FlightMode.TAKEOFF


def test_the_same_commands_are_accepted_disarmed_or_in_the_air():
    for armed, landed in ((False, False), (True, False)):
        c = _commander()
        c.armed, c.landed = armed, landed
        for command, params, _ in AIRBORNE_ONLY:
            assert _asks(c, command, *params)[0] == CommandResult.ACCEPTED, command


def test_what_the_operator_is_told_armed_on_the_ground():
    no_takeoff = [speed(0, 10.0), wp(1, (0.0, 900.0)), wp(2, (900.0, 900.0))]
    takeoff = [item(0, d.MAV_CMD_NAV_TAKEOFF, None, z=50.0), *no_takeoff[1:]]
    assert first_to_fly(no_takeoff, 0) == no_takeoff[1]  # the speed change passed
    text = "Mission item 1 not a take-off: taking off first"
    assert ground_notice(FlightMode.MISSION, no_takeoff, 0) == text
    assert ground_notice(FlightMode.MISSION, takeoff, 0) is None  # it takes off as planned
    # Started at item 2 (MISSION_START's first item): that one is not a take-off either.
    assert ground_notice(FlightMode.MISSION, takeoff, 2) == text.replace("1", "2")
    holding = "Hold: on the ground until Takeoff or Mission"  # Loiter, as QGroundControl names it
    assert ground_notice(FlightMode.LOITER, takeoff, 0) == holding
    assert ground_notice(FlightMode.RTL, [], 0) == holding.replace("Hold", "Return")
    assert ground_notice(FlightMode.TAKEOFF, [], 0) is None
    assert ground_notice(FlightMode.MANUAL, [], 0) is None


def test_standing_is_judged_from_the_solution_until_the_controller_speaks():
    nav = NavState(flags=int(NavFlags.POSITION_VALID))
    nav.alt_msl_m = 81.0
    assert standing(nav, 80.0) is True  # just armed on the runway
    nav.vn_m_s = 25.0
    assert standing(nav, 80.0) is False  # flying speed
    nav.vn_m_s, nav.alt_msl_m = 0.0, 200.0
    assert standing(nav, 80.0) is False  # far above home
    assert standing(None, 80.0) is None and standing(nav, None) is None
