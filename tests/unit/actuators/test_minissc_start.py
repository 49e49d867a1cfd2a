"""actuators.minissc started in a held simulation: a clock that has not heard the simulator
yet must not make the first command look seconds old."""

from __future__ import annotations

import logging
import os
import select
from pathlib import Path
from types import SimpleNamespace

from companion.actuators.airframe import load_airframe
from companion.actuators.minissc import FrameDecoder
from companion.messages import ActuatorCommand, ControlStatus
from companion.plugin import PluginContext
from companion.plugins.actuators.minissc import MiniSscOutput
from tests.support.pty import Pty


class _Commands:
    def __init__(self) -> None:
        self.queued: list[ActuatorCommand] = []

    def pending(self) -> list[ActuatorCommand]:
        taken, self.queued = self.queued, []
        return taken


class _Bus:
    """The ports the plug-in opens: its commands, its wait, its answers, the controller's
    status, and ``link/commands`` (DO_SET_SERVO's), where nothing comes here."""

    def __init__(self, status: ControlStatus | None = None) -> None:
        self.commands = _Commands()
        self.requests = _Commands()
        self.status = status

    def latest_reader(self, name: str) -> SimpleNamespace:
        assert name == "control/status"
        return SimpleNamespace(get=lambda: self.status)

    def queue_reader(self, name: str) -> _Commands:
        return self.requests if name == "link/commands" else self.commands

    def waiter(self, readers) -> SimpleNamespace:
        return SimpleNamespace(sleep=lambda timeout_s: None, close=lambda: None)

    def writer(self, name: str) -> SimpleNamespace:
        return SimpleNamespace(publish=lambda msg: None)


class _Clock:
    def __init__(self) -> None:
        self.us = 0

    def now_us(self) -> int:
        return self.us


def started_servos(
    tmp_path: Path, supervisor_pid: int | None = None, status: ControlStatus | None = None
) -> tuple[MiniSscOutput, _Bus, _Clock, Pty]:
    """The plug-in on a pty, with stand-ins for its bus ports and its clock (a C172)."""
    pty = Pty(tmp_path / "ttyServo")
    os.set_blocking(pty.master, False)
    bus, clock = _Bus(status), _Clock()
    settings = {"device": str(pty.link), "baud": 9600, "stale_s": 0.5, "flight_hold_s": 2.0}
    servos = MiniSscOutput()
    vehicle = {"airframe": "c172p", "state_dir": str(tmp_path)}
    ctx = PluginContext("servos", settings, logging.getLogger("servos"), bus, clock, vehicle)  # type: ignore[arg-type]
    ctx.supervisor_pid = supervisor_pid
    servos.init(ctx)
    return servos, bus, clock, pty


def test_a_wake_up_just_after_the_first_command_keeps_the_commanded_throttle(tmp_path):
    servos, bus, clock, pty = started_servos(tmp_path)
    throttle = next(c for c in load_airframe("c172p").channels if c.surface == "throttle")
    # Started at START at 5 s of simulation: the first command (answering the navigator's
    # state of 5.00 s) comes while this process's clock still reads 0; the next wake-up
    # (a wall-clock timeout, no command yet) comes once the simulator's next frame, 5.01 s.
    bus.commands.queued.append(ActuatorCommand(t_us=5_000_000, armed=1, throttle=1.0))
    servos.step()
    clock.us = 5_010_000
    servos.step()
    card, positions = FrameDecoder(), {}
    for servo, position in card.feed(_written(pty.master)):
        positions[servo] = position
    servos.close()
    pty.vanish()
    assert positions[throttle.servo] == throttle.position(1.0) != throttle.safe


def _written(master: int) -> bytes:
    """What reached the card (the kernel hands a pty's bytes over a moment after the write)."""
    data = b""
    while select.select([master], [], [], 0.2)[0]:
        data += os.read(master, 4096)
    return data


def _decoded(master: int) -> dict[int, int]:
    return dict(FrameDecoder().feed(_written(master)))


def test_restarted_in_flight_it_writes_nothing_until_the_first_command(tmp_path):
    # The servo process crashed and was restarted while the controller says "flying":
    # safe positions now would cut the throttle in the air for the controller's first cycle.
    servos, bus, clock, pty = started_servos(tmp_path, status=ControlStatus(t_us=1, landed=0))
    throttle = next(c for c in load_airframe("c172p").channels if c.surface == "throttle")
    clock.us = 30_000_000
    servos.step()
    clock.us += 1_000_000  # within flight_hold_s (2 s)
    servos.step()
    assert _written(pty.master) == b""  # the card keeps the pulses it had
    bus.commands.queued.append(ActuatorCommand(t_us=clock.us, armed=1, throttle=0.8))
    servos.step()
    positions = _decoded(pty.master)
    assert positions[throttle.servo] == throttle.position(0.8)
    assert len(positions) == len(load_airframe("c172p").channels)  # every channel, once
    clock.us += 2_500_000  # then silence past flight_hold_s: safe positions after all
    servos.step()
    assert _decoded(pty.master)[throttle.servo] == throttle.safe
    servos.close()
    pty.vanish()


def test_started_on_the_ground_every_channel_goes_safe_at_once(tmp_path):
    servos, _, _, pty = started_servos(tmp_path, status=ControlStatus(t_us=1, landed=1))
    safe = {c.servo: c.safe for c in load_airframe("c172p").channels}
    assert _decoded(pty.master) == safe
    servos.close()
    pty.vanish()


def test_a_card_trimmed_as_the_supervisor_died_is_held_by_the_restarted_vehicle(tmp_path):
    servos, bus, clock, pty = started_servos(tmp_path, supervisor_pid=-1)
    bus.commands.queued.append(ActuatorCommand(t_us=1_000_000, armed=1, throttle=0.7))
    clock.us = 1_000_000
    servos.step()
    servos.close()  # the supervisor is gone: trimmed, and the restarted vehicle told so
    pty.vanish()
    assert (tmp_path / "servos_held_in_flight").exists()
    # The restarted vehicle has no controller status yet (its bus started empty).
    again, _, _, pty = started_servos(tmp_path)
    assert _written(pty.master) == b""
    assert not (tmp_path / "servos_held_in_flight").exists()  # said once
    again.close()
    pty.vanish()
    # A mark older than a restart takes says nothing: a later start is a start on the ground.
    mark = tmp_path / "servos_held_in_flight"
    mark.write_text("old\n")
    os.utime(mark, (1.0, 1.0))
    third, _, _, pty = started_servos(tmp_path)
    assert _decoded(pty.master) == {c.servo: c.safe for c in load_airframe("c172p").channels}
    third.close()
    pty.vanish()
