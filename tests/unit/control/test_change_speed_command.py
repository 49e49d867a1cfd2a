"""DO_CHANGE_SPEED at the commander: the speed goes into the status and holds until the
mode changes (but for a take-off's end in Hold, as PX4's navigator keeps it) or the
aircraft is disarmed."""

from __future__ import annotations

import math

from companion.control.commander import Commander
from companion.messages import CommandId, CommandResult, FlightMode, VehicleCommand


def _command(c: Commander, kind: CommandId, *params: float) -> CommandResult:
    cmd = VehicleCommand(command=int(kind))
    for i, value in enumerate(params):
        cmd.param[i] = value
    decision = c.handle(cmd)
    assert decision is not None
    return decision.result


def _flying() -> Commander:
    c = Commander(lambda: 3)
    c.position = (-37.9, 145.1, 200.0)
    c.home = (-37.9, 145.1, 100.0)
    c.on_armed(True)
    return c


def test_the_speed_holds_in_its_mode_and_is_forgotten_on_a_change_of_mode():
    c = _flying()
    assert _command(c, CommandId.SET_MODE, float(FlightMode.MISSION)) == CommandResult.ACCEPTED
    assert math.isnan(c.status(0).speed_m_s)
    assert _command(c, CommandId.CHANGE_SPEED, 42.0) == CommandResult.ACCEPTED
    assert c.status(0).speed_m_s == 42.0
    assert _command(c, CommandId.SET_MODE, float(FlightMode.MISSION)) == CommandResult.ACCEPTED
    assert c.status(0).speed_m_s == 42.0  # the same mode again: kept
    assert _command(c, CommandId.LOITER, math.nan, math.nan, math.nan) == CommandResult.ACCEPTED
    assert math.isnan(c.status(0).speed_m_s)  # Hold: the cruise airspeed again


def test_the_default_again_a_takeoffs_hold_and_the_end_of_the_flight():
    c = _flying()
    assert _command(c, CommandId.TAKEOFF, math.nan, math.nan, math.nan) == CommandResult.ACCEPTED
    _command(c, CommandId.CHANGE_SPEED, 40.0)
    assert c.failsafe(FlightMode.LOITER).result == CommandResult.ACCEPTED
    assert c.status(0).speed_m_s == 40.0  # the take-off's hold keeps it, as PX4's
    _command(c, CommandId.CHANGE_SPEED, math.nan)  # -2 at the link: back to the default
    assert math.isnan(c.status(0).speed_m_s)
    _command(c, CommandId.CHANGE_SPEED, 40.0)
    c.on_armed(False)
    assert math.isnan(c.status(0).speed_m_s)  # the next flight starts at the cruise


def test_a_speed_that_is_no_speed_is_refused_and_changes_nothing():
    c = _flying()
    _command(c, CommandId.CHANGE_SPEED, 40.0)
    for bad in (math.inf, -math.inf, 0.0, -3.0):
        assert _command(c, CommandId.CHANGE_SPEED, bad) == CommandResult.DENIED
    assert c.status(0).speed_m_s == 40.0
