"""sensors.rc_input on a real pseudo-terminal: sticks and the mode switch come through
garbage, the receiver's failsafe flag is passed on, and nothing restarts."""

from __future__ import annotations

import os

import pytest

from companion.messages import PilotFlags, PilotInput
from tests.support.configs import plugin, vehicle_config
from tests.support.pty import Pty
from tests.support.sbus import frame, us_to_raw
from tests.support.vehicle import wait_for

CENTRE = [us_to_raw(1500)] * 16


def pulses(roll: int = 1500, throttle: int = 1100, switch: int = 1100) -> list[int]:
    ch = list(CENTRE)
    ch[0], ch[2], ch[7] = us_to_raw(roll), us_to_raw(throttle), us_to_raw(switch)
    return ch


@pytest.mark.timeout(240)
def test_sticks_switch_and_failsafe_through_garbage(vehicle_factory, tmp_path):
    device = tmp_path / "ttyRC"
    pty = Pty(device)
    rc = plugin("rc", "sensors.rc_input", device=str(device))
    vehicle = vehicle_factory(vehicle_config("rc", rc))
    sticks = vehicle.bus.latest_reader("sensors/rc")
    every = vehicle.bus.latest_reader("sensors/rc", keep=16)  # each frame, to count them
    switch = vehicle.bus.queue_reader("sensors/rc_switch")
    vehicle.wait_running("rc")

    def send(data: bytes) -> None:
        os.write(pty.master, data)

    def seen(roll: float) -> bool:
        send(b"\x0f\xff\x00garbage" + frame(pulses(roll=1900, throttle=1500)))
        got = sticks.get()
        return got is not None and got.roll == pytest.approx(roll, abs=0.01)

    wait_for(lambda: seen(1.0), 60, "full right roll")  # a minute, as on a busy machine
    # The switch's start position is noted once two frames running show it: a driver may
    # have decoded only the first when the test sees its roll.
    at_start: list[PilotInput] = []

    def start_noted() -> bool:
        at_start.extend(s for s in every.drain() if s.mode_switch == 0)
        if len(at_start) < 2:
            send(frame(pulses(roll=1900, throttle=1500)))
        return len(at_start) >= 2

    wait_for(start_noted, 30, "two frames at the switch's start position")
    got = sticks.get()
    assert got.throttle == pytest.approx(0.5, abs=0.01) and got.mode_switch == 0
    assert got.usable() and got.channels_us[0] == 1900 and got.channel_count == 18
    assert switch.take(0.3) == []  # where the switch stood at start is only noted

    def moved() -> bool:
        send(frame(pulses(switch=1900)) * 2)
        return any(s.mode_switch == 5 for s in switch.take(0.2))

    wait_for(moved, 30, "the switch moved to position 6")
    send(frame(pulses(throttle=900), flags=0x08) * 2)  # the receiver's failsafe
    failsafe = PilotFlags.FAILSAFE | PilotFlags.THROTTLE_LOW
    wait_for(lambda: (s := sticks.get()) is not None and s.flags == failsafe, 30, "failsafe")
    wait_for(lambda: vehicle.row("rc").frames_bad >= 1, 30, "the garbage counted")
    assert vehicle.row("rc").restarts == 0
    pty.vanish()
