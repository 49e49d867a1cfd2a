"""When the supervisor dies, the servo card is left holding the surfaces the aircraft was
flying on lately (not the dead controller's last frame, not the card's centre)."""

from __future__ import annotations

import math

import pytest

from companion.actuators.airframe import load_airframe
from companion.actuators.flying_trim import FlyingTrim
from companion.actuators.minissc import FrameDecoder
from companion.messages import ActuatorCommand
from tests.unit.actuators.test_minissc_start import _written, started_servos


def test_the_average_follows_a_steady_command_and_forgets_an_old_one():
    trim = FlyingTrim(tau_s=2.0)
    assert trim.position(1, 127) == 127  # never flown: the default
    for i in range(500):  # 10 s at 50 Hz on 150, then 1 s on 100
        trim.update({1: 150 if i < 450 else 100}, i * 0.02)
    # After 1 s of a new command, 1 - exp(-1/2) of the way there.
    assert trim.position(1, 127) == round(100 + 50 * math.exp(-0.5))


def test_a_gap_in_the_commands_weighs_as_the_time_it_lasted():
    trim = FlyingTrim(tau_s=2.0)
    trim.update({1: 0}, 0.0)
    trim.update({1: 200}, 2.0)  # one command, 2 s later
    assert trim.positions[1] == pytest.approx(200 * (1 - math.exp(-1.0)))


def test_with_the_supervisor_gone_the_card_holds_the_surfaces_flown_lately(tmp_path):
    # A supervisor pid not this process's parent: the supervisor is gone.
    servos, bus, clock, pty = started_servos(tmp_path, supervisor_pid=-1)
    channels = {c.surface: c for c in load_airframe("c172p").channels}
    # 4 s of a straight leg (a little right aileron, some up elevator, cruise power),
    # then the last command before the death: rolling hard left into a turn.
    for i in range(200):
        clock.us = i * 20_000
        cmd = ActuatorCommand(t_us=clock.us, armed=1, throttle=0.7)
        cmd.aileron, cmd.elevator = 0.05 + 0.02 * math.sin(i), -0.2
        bus.commands.queued.append(cmd)
        servos.step()
    clock.us += 20_000
    last = ActuatorCommand(t_us=clock.us, armed=1, aileron=-1.0, elevator=-0.5, throttle=0.7)
    bus.commands.queued.append(last)
    servos.step()
    servos.close()
    positions = dict(FrameDecoder().feed(_written(pty.master)))
    pty.vanish()
    aileron, elevator = channels["aileron"], channels["elevator"]
    assert abs(positions[aileron.servo] - aileron.position(0.05)) <= 3  # not full left
    assert abs(positions[elevator.servo] - elevator.position(-0.2)) <= 3
    assert positions[aileron.servo] != aileron.safe
    throttle = channels["throttle"]
    assert positions[throttle.servo] == throttle.position(0.7)  # held, not cut
