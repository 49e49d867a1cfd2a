"""Manual and Stabilized (FBWA) flown from a pilot's sticks, on JSBSim, and the choice of
whose sticks those are."""

from __future__ import annotations

import math

import numpy as np
import pytest

from companion.control.flight.attitude_modes import STICKS_STALE_US, Sticks, pilot_sticks
from companion.messages import FlightMode, PilotFlags, PilotInput, PilotSource
from tests.support.closed_loop import ClosedLoop


def flying(mode: FlightMode, sticks: Sticks) -> ClosedLoop:
    return ClosedLoop(mode=mode, airborne_agl_m=300.0, sticks=sticks)


def test_manual_puts_the_sticks_on_the_surfaces_in_the_same_cycle():
    loop = flying(FlightMode.MISSION, Sticks(0.3, -0.2, 0.1, 0.8))
    loop.run(1.0)
    loop.set_mode(FlightMode.MANUAL)
    loop.run(0.02)  # one control cycle
    out = loop.samples[-1].out
    assert (out.aileron, out.elevator, out.rudder, out.throttle) == (0.3, -0.2, 0.1, 0.8)


def test_stabilized_banks_to_the_stick_and_levels_hands_off():
    loop = flying(FlightMode.STABILIZED, Sticks(0.5, 0.0, 0.0, 0.6))
    loop.run(10.0)
    roll = np.degrees([s.roll for s in loop.samples[-200:]])
    limit_deg = math.degrees(loop.controller.config.roll_limit)  # the airframe's
    assert roll.mean() == pytest.approx(0.5 * limit_deg, abs=2.0)
    loop.sticks = Sticks(0.0, 0.0, 0.0, 0.6)
    loop.run(8.0)
    assert abs(math.degrees(loop.samples[-1].roll)) < 3.0


def test_stabilized_pitch_stick_climbs_and_throttle_is_the_pilots():
    loop = flying(FlightMode.STABILIZED, Sticks(0.0, 0.4, 0.0, 1.0))
    loop.run(10.0)
    alt = [s.alt_msl for s in loop.samples]
    assert alt[-1] - alt[len(alt) // 2] > 10.0  # climbing
    assert all(s.out.throttle == 1.0 for s in loop.samples)


def _input(t_us: int, source: PilotSource, roll: float, flags: int = 0) -> PilotInput:
    p = PilotInput(t_us=t_us, source=source, flags=flags)
    p.roll, p.pitch, p.yaw, p.throttle = roll, 0.0, 0.0, 0.5
    return p


def test_the_receiver_wins_and_stale_or_failsafe_sticks_are_not_flown():
    now = 10_000_000
    rc = _input(now, PilotSource.RC, 0.2)
    joy = _input(now, PilotSource.MANUAL_CONTROL, -0.7)
    assert pilot_sticks(now, rc, joy).roll == 0.2
    failsafe = _input(now, PilotSource.RC, 0.2, int(PilotFlags.FAILSAFE))
    assert pilot_sticks(now, failsafe, joy).roll == -0.7
    stale = _input(now - STICKS_STALE_US - 1, PilotSource.RC, 0.2)
    assert pilot_sticks(now, stale, None) is None
    assert pilot_sticks(now, _input(now, PilotSource.RC, math.nan), None) is None
    assert pilot_sticks(now, _input(now, PilotSource.RC, 7.0), None).roll == 1.0
