"""No command sends the aircraft under the floor: GUIDED_ALT_MIN above home. A target
under it is refused with the reason; one without an altitude (NaN, or 0 as the link
reads it) is flown at the present altitude, or at the floor when the aircraft is lower."""

from __future__ import annotations

import math

from pymavlink.dialects.v20 import common as m

from companion.control.commander import Commander
from companion.link.command_rules import refusal
from companion.link.commands import ModeCommands
from companion.messages import (
    CommandId,
    CommandResult,
    FlightMode,
    NavFlags,
    NavState,
    VehicleCommand,
)
from tests.support.vehicle_port import RecordingVehicle
from tests.unit.link.test_command_groups import args

HOME = (-37.9105, 145.134, 120.0)
NAN = math.nan


def _at(c: Commander, alt: float) -> None:
    nav = NavState(flags=int(NavFlags.POSITION_VALID))
    nav.lat_deg, nav.lon_deg, nav.alt_msl_m = HOME[0], HOME[1], alt
    c.on_nav(nav)


def _commander(height_now: float) -> Commander:
    c = Commander(lambda: 3, min_height=lambda: 30.0)
    _at(c, HOME[2])  # home from the first fix, on the ground
    c.on_armed(True)
    _at(c, HOME[2] + height_now)
    return c


def _send(c: Commander, kind: CommandId, *p: float):
    cmd = VehicleCommand(command=int(kind))
    for i, v in enumerate(p):
        cmd.param[i] = v
    decision = c.handle(cmd)
    assert decision is not None
    return decision


def test_targets_under_the_floor_are_refused_with_the_reason():
    c = _commander(100.0)
    for kind, p in (
        (CommandId.REPOSITION, (HOME[0] + 0.01, HOME[1], HOME[2] + 10.0)),  # go to, low
        (CommandId.REPOSITION, (NAN, NAN, HOME[2] - 5.0)),  # change altitude: underground
        (CommandId.LOITER, (NAN, NAN, 0.0)),  # 0 m above sea level, read as real
        (CommandId.ORBIT, (HOME[0], HOME[1], HOME[2] + 29.0, 150.0)),
        (CommandId.TAKEOFF, (NAN, NAN, HOME[2] + 20.0)),
    ):
        decision = _send(c, kind, *p)
        assert decision.result == CommandResult.DENIED, kind
        assert "below GUIDED_ALT_MIN 30 m" in decision.reason, decision.reason
    assert c.mode == FlightMode.LOITER and math.isnan(c.target[2])  # nothing changed
    assert _send(c, CommandId.REPOSITION, NAN, NAN, HOME[2] + 30.0).result == 0  # the floor


def test_no_altitude_is_the_present_one_and_never_under_the_floor():
    high = _commander(100.0)
    assert _send(high, CommandId.LOITER, NAN, NAN, NAN).result == CommandResult.ACCEPTED
    assert high.target[2] == HOME[2] + 100.0
    low = _commander(12.0)  # just off the runway
    assert _send(low, CommandId.LOITER, NAN, NAN, NAN).result == CommandResult.ACCEPTED
    assert low.target[2] == HOME[2] + 30.0
    go = _send(low, CommandId.REPOSITION, HOME[0] + 0.01, HOME[1], NAN)
    assert go.result == CommandResult.ACCEPTED and low.target[2] == HOME[2] + 30.0


def test_the_link_reads_every_parameter_zero_as_here_at_the_present_altitude():
    """QGroundControl's custom action: NAV_LOITER_UNLIM with every parameter 0."""
    vehicle = RecordingVehicle()
    modes = ModeCommands(vehicle, m.MAV_AUTOPILOT_PX4)
    for command, handler in ((m.MAV_CMD_NAV_LOITER_UNLIM, modes.loiter),
                             (m.MAV_CMD_DO_REPOSITION, modes.reposition),
                             (m.MAV_CMD_NAV_TAKEOFF, modes.takeoff)):  # fmt: skip
        vehicle.published.clear()
        handler(args(command))
        _, point = vehicle.published[0]
        assert all(math.isnan(v) for v in point[:3]), (command, point)


def test_a_home_at_0_0_is_refused_as_every_parameter_0_sends_it():
    """DO_SET_HOME sent with every parameter 0 would move home (and with it Return and the
    height floor) to 0°, 0° at sea level; "use current" (param1 1) or a real point pass."""
    home = m.MAV_CMD_DO_SET_HOME
    assert "0, 0 is no home" in (refusal(args(home)) or "")
    assert refusal(args(home, 1)) is None
    assert refusal(args(home, 0, 0, 0, 0, HOME[0], HOME[1], HOME[2])) is None
