"""MAV_CMD_DO_GO_AROUND at the commander: accepted only while a landing can still be
aborted (on the approach or in the flare), and then passed to the flight controller."""

from __future__ import annotations

from companion.control.commander import Commander
from companion.messages import CommandId, CommandResult, VehicleCommand


def _go_around(c: Commander) -> CommandResult:
    decision = c.handle(VehicleCommand(command=int(CommandId.GO_AROUND)))
    assert decision is not None
    return decision.result


def test_go_around_is_refused_unless_landing_and_counted_when_accepted():
    c = Commander(lambda: 3)
    assert _go_around(c) == CommandResult.DENIED  # cruising: nothing to abort
    assert c.status(0).go_arounds == 0
    c.land_phase = 1  # the controller reports the approach
    assert _go_around(c) == CommandResult.ACCEPTED
    assert c.status(0).go_arounds == 1
    c.land_phase = 3  # on the wheels: too late
    assert _go_around(c) == CommandResult.DENIED
    assert c.status(0).go_arounds == 1
