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
from companion.messages import ActuatorCommand
from companion.plugin import PluginContext
from companion.plugins.actuators.minissc import MiniSscOutput
from tests.support.pty import Pty


class _Commands:
    def __init__(self) -> None:
        self.pending: list[ActuatorCommand] = []

    def drain(self):
        while self.pending:
            yield self.pending.pop(0)


class _Bus:
    """The three ports the plug-in opens: its commands, its wait, its answers."""

    def __init__(self) -> None:
        self.commands = _Commands()

    def queue_reader(self, name: str) -> _Commands:
        return self.commands

    def waiter(self, readers) -> SimpleNamespace:
        return SimpleNamespace(wait=lambda timeout_s: [], close=lambda: None)

    def writer(self, name: str) -> SimpleNamespace:
        return SimpleNamespace(publish=lambda msg: None)


class _Clock:
    def __init__(self) -> None:
        self.us = 0

    def now_us(self) -> int:
        return self.us


def started_servos(
    tmp_path: Path, supervisor_pid: int | None = None
) -> tuple[MiniSscOutput, _Bus, _Clock, Pty]:
    """The plug-in on a pty, with stand-ins for its bus ports and its clock (a C172)."""
    pty = Pty(tmp_path / "ttyServo")
    os.set_blocking(pty.master, False)
    bus, clock = _Bus(), _Clock()
    settings = {"device": str(pty.link), "baud": 9600, "stale_s": 0.5, "flight_hold_s": 2.0}
    servos = MiniSscOutput()
    ctx = PluginContext(
        "servos", settings, logging.getLogger("servos"), bus, clock, {"airframe": "c172p"}
    )  # type: ignore[arg-type]
    ctx.supervisor_pid = supervisor_pid
    servos.init(ctx)
    return servos, bus, clock, pty


def test_a_wake_up_just_after_the_first_command_keeps_the_commanded_throttle(tmp_path):
    servos, bus, clock, pty = started_servos(tmp_path)
    throttle = next(c for c in load_airframe("c172p").channels if c.surface == "throttle")
    # Started at START at 5 s of simulation: the first command (answering the navigator's
    # state of 5.00 s) comes while this process's clock still reads 0; the next wake-up
    # (a wall-clock timeout, no command yet) comes once the simulator's next frame, 5.01 s.
    bus.commands.pending.append(ActuatorCommand(t_us=5_000_000, armed=1, throttle=1.0))
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
