"""actuators.minissc on a real pty: frames, channel map, reversal, limits, safe positions."""

from __future__ import annotations

import os
import time

import pytest

from companion.actuators.airframe import load_airframe
from companion.actuators.minissc import FrameDecoder, pulse_us
from companion.messages import ActuatorCommand, CommandId, CommandResult, VehicleCommand
from tests.support.configs import plugin, vehicle_config
from tests.support.pty import Pty
from tests.support.vehicle import wait_for


class CardEnd:
    """The servo card's side of the line: decodes what the plug-in writes."""

    def __init__(self, pty: Pty) -> None:
        self.pty = pty
        os.set_blocking(pty.master, False)
        self.decoder = FrameDecoder()
        self.positions: dict[int, int] = {}
        self.frames = 0

    def poll(self) -> dict[int, int]:
        try:
            data = os.read(self.pty.master, 4096)
        except BlockingIOError:
            data = b""
        for servo, position in self.decoder.feed(data):
            self.positions[servo] = position
            self.frames += 1
        return self.positions


def command(**surfaces: float) -> ActuatorCommand:
    msg = ActuatorCommand(t_us=0, armed=1)
    for name, value in surfaces.items():
        setattr(msg, name, value)
    return msg


def start_servos(vehicle_factory, tmp_path, airframe: str):
    pty = Pty(tmp_path / "ttyServo")
    servos = plugin(
        "servos", "actuators.minissc", "flight", device=pty.link, stale_s=0.3, flight_hold_s=1.5
    )
    vehicle = vehicle_factory(vehicle_config("servos", servos, airframe=airframe))
    card = CardEnd(pty)
    commands = vehicle.bus.writer("link/commands")
    wait_for(vehicle.health, 60, "the execution control's health table")

    def started() -> bool:  # repeated: START sent before the supervisor listens is lost
        commands.publish(VehicleCommand(t_us=0, seq=1, command=int(CommandId.START)))
        return bool((row := vehicle.row("servos")) and row.pid)

    wait_for(started, 60, "servo output started", period_s=0.5)
    return vehicle, card, commands


@pytest.mark.timeout(180)  # start-up takes up to a minute on a busy machine
def test_commands_reach_the_card_through_the_channel_map(vehicle_factory, tmp_path):
    vehicle, card, commands = start_servos(vehicle_factory, tmp_path, "J3Cub")
    cub = load_airframe("J3Cub")
    safe = {c.servo: c.safe for c in cub.channels}
    wait_for(lambda: card.poll() == safe, 10, "safe positions at start")

    actuators = vehicle.bus.writer("control/actuators")
    servos = vehicle.bus.latest_reader("actuators/servos")
    ail, elev, thr = cub.channel("aileron"), cub.channel("elevator"), cub.channel("throttle")
    want = {ail.servo: ail.max, elev.servo: elev.max, thr.servo: thr.min + (thr.max - thr.min) // 2}

    def commanded() -> bool:
        # Nose down is elevator -1: the Cub's elevator servo is reversed, so that is its max;
        # an aileron command of 5 is clamped to full travel.
        actuators.publish(command(aileron=5.0, elevator=-1.0, throttle=0.5))
        positions = card.poll()
        return all(positions.get(s) in (p, p + 1) for s, p in want.items())

    wait_for(commanded, 10, "the commanded positions on the wire")
    assert vehicle.row("servos").restarts == 0
    # The servo output says what it wrote after writing it: the card can be ahead of the bus.
    written = wait_for(
        lambda: (w := servos.get()) and w.pulse_us[ail.servo] == pulse_us(ail.max) and w,
        5,
        "the servo output's answer with the aileron's pulse",
    )
    assert written.position[elev.servo] == elev.max

    # Armed input stops (a controller restarting in flight): the last positions are held
    # past stale_s, then every channel goes back to safe, throttle off.
    stopped = time.monotonic()
    time.sleep(0.8)
    held = card.poll()
    if time.monotonic() - stopped < 1.2:  # judged only when this test was not held up itself
        assert held[thr.servo] in (want[thr.servo], want[thr.servo] + 1), held
    wait_for(lambda: card.poll() == safe, 5, "safe positions once commands stop")

    wait_for(
        lambda: actuators.publish(command(throttle=1.0)) or card.poll()[thr.servo] == thr.max,
        5,
        "full throttle",
    )
    commands.publish(VehicleCommand(t_us=0, seq=2, command=int(CommandId.STOP)))
    wait_for(lambda: vehicle.row("servos").pid == 0, 10, "servo output stopped")
    wait_for(lambda: card.poll() == safe, 5, "safe positions written on STOP")


@pytest.mark.timeout(180)  # start-up takes up to a minute on a busy machine
def test_a_disarmed_command_means_safe_positions(vehicle_factory, tmp_path):
    vehicle, card, _ = start_servos(vehicle_factory, tmp_path, "c172p")
    c172 = load_airframe("c172p")
    actuators = vehicle.bus.writer("control/actuators")
    aileron = c172.channel("aileron")

    def deflected() -> bool:
        actuators.publish(command(aileron=-1.0, throttle=0.8))
        return card.poll().get(aileron.servo) == aileron.min

    wait_for(deflected, 10, "aileron full left")
    safe = {c.servo: c.safe for c in c172.channels}

    def disarmed() -> bool:
        msg = command(aileron=-1.0, throttle=0.8)
        msg.armed = 0
        actuators.publish(msg)
        return card.poll() == safe

    wait_for(disarmed, 5, "safe positions on a disarmed command")


@pytest.mark.timeout(180)  # start-up takes up to a minute on a busy machine
def test_set_servo_moves_a_spare_output_and_refuses_a_surfaces(vehicle_factory, tmp_path):
    """DO_SET_SERVO as the link puts it on the bus: output 7 (the card's servo 6, which the
    c172p leaves spare) goes to the pulse asked for and is refreshed with the surfaces;
    output 2 (the elevator) is refused with the reason; STOP leaves the spare one as set."""
    vehicle, card, commands = start_servos(vehicle_factory, tmp_path, "c172p")
    c172 = load_airframe("c172p")
    safe = {c.servo: c.safe for c in c172.channels}
    wait_for(lambda: card.poll() == safe, 10, "safe positions at start")
    acks = vehicle.bus.queue_reader("link/command_acks")

    def answer(seq: int, output: int, pulse: int):
        def answered():
            cmd = VehicleCommand(t_us=0, seq=seq, command=int(CommandId.SET_SERVO))
            cmd.param[0], cmd.param[1] = output, pulse
            commands.publish(cmd)
            return next((a for a in acks.pending() if a.seq == seq), None)

        return wait_for(answered, 10, f"the answer to SET_SERVO {output} {pulse}", 0.5)

    release = answer(10, 7, 1900)
    assert release.result == CommandResult.ACCEPTED and release.source == b"servos"
    wait_for(lambda: card.poll().get(6) == 229, 5, "servo 6 at 1900 us")  # (1900-1000)*254/1000
    refused = answer(11, 2, 1500)
    assert refused.result == CommandResult.DENIED
    assert refused.reason == b"Set servo: output 2 drives the elevator"

    actuators = vehicle.bus.writer("control/actuators")
    servos = vehicle.bus.latest_reader("actuators/servos")
    frames = card.frames
    wait_for(
        lambda: (
            actuators.publish(command(aileron=0.2, throttle=0.5))
            or (card.poll() and card.frames > frames + 40)
        ),
        10,
        "refreshes while commands flow",
    )
    assert card.poll()[6] == 229 and card.poll()[1] == safe[1]
    shown = wait_for(lambda: (s := servos.get()) and s.pulse_us[6] and s, 5, "SERVO_OUTPUT")
    assert shown.pulse_us[6] == 1902  # the card's own step nearest 1900 us
    commands.publish(VehicleCommand(t_us=0, seq=12, command=int(CommandId.STOP)))
    wait_for(lambda: vehicle.row("servos").pid == 0, 10, "servo output stopped")
    wait_for(lambda: card.poll() == {**safe, 6: 229}, 5, "surfaces safe, the release held")
