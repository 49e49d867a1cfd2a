"""``actuators.minissc``: surface commands to a Mini SSC II servo card on a serial port.

Group ``flight``: it runs while the vehicle is started (armed). On STOP (its process is
stopped), when its command input goes stale, or when a command says disarmed, every
channel goes to its safe position: throttle off, surfaces at trim. Armed, the last
positions are held a while longer (``flight_hold_s``) before the input counts as stale, so
that a controller restarting in flight finds the aircraft as it left it. When the supervisor
itself dies, the whole vehicle restarts (seconds on a busy board): the flight surfaces go
to the trim the aircraft was flying on (each surface's command averaged over the last
seconds, ``companion.actuators.flying_trim``), as ArduPilot sets its I/O co-processor's
failsafe outputs when the flight computer stops, and the card holds them and the throttle
until the restarted controller commands it. Holding the last surfaces instead held
whatever the controller was doing: killed while rolling into a turn with full aileron, the
aircraft rolled on at 40°/s and was inverted and in the ground 6 s later, before the
vehicle was back; the card's centre positions rolled it 35° in a second.

An output the airframe leaves spare (none of its surfaces' servos) is set by
MAV_CMD_DO_SET_SERVO, a command or a mission item, which comes as SET_SERVO on
``link/commands`` and is answered on ``link/command_acks``; one that drives a surface is
refused with the reason. Armed, it is written and refreshed with the surfaces; stopped,
it is not written again, and the card holds its pulse.

Started in flight (this process restarted after a crash while the controller says the
aircraft is not landed, or the vehicle restarted after its supervisor died and the card was
left trimmed), nothing is written until the first command: the card keeps its last pulses,
and the safe positions written at a start on the ground would cut the throttle in the air.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from companion.actuators import minissc
from companion.actuators.airframe import SERVO_IDS, Airframe, load_airframe
from companion.actuators.flying_trim import FlyingTrim
from companion.messages import (
    CAMERA_SEQ,
    ActuatorCommand,
    CommandAck,
    CommandId,
    CommandResult,
    ServoOutput,
    VehicleCommand,
)
from companion.messages.base import packed_layout
from companion.params.atomic import atomic_write_text
from companion.plugin import FLIGHT_NICE, NO_VEHICLE, DeviceProbe, Plugin, PluginContext, Setting
from companion.sensors.serial_port import ReopeningSerial, open_problem

WAIT_S = 0.1  # also the refresh cadence when no command arrives
CYCLE_MIN_S, CYCLE_MAX_S = 0.01, 0.1
FRAME_BYTES = 3
# Trimmed when the supervisor dies; the rest (throttle, flaps, brakes) is held.
FLIGHT_SURFACES = ("aileron", "elevator", "rudder")
# Left by a process that trimmed the card as its supervisor died, for the restarted vehicle's
# servo plug-in; older than this (wall seconds) it says nothing of the card.
HELD_MARK_MAX_S = 60.0


# A command read in one call, 50 times a second (a ctypes field read makes an object, the
# ``aux`` array one more each time), in the registry's layout.
_COMMAND, _COMMAND_AT = packed_layout(ActuatorCommand)
_ARMED = _COMMAND_AT["armed"]
# Where each driven surface's command is in it: ``flaps`` is aux[0], ``brakes`` aux[1];
# other extras are not driven.
SURFACE_AT = {name: _COMMAND_AT[name] for name in ("aileron", "elevator", "rudder", "throttle")}
SURFACE_AT |= {"flaps": _COMMAND_AT["aux"], "brakes": _COMMAND_AT["aux"] + 1}
# ServoOutput made in one call from its packed fields instead of a dozen ctypes field and
# item writes.
_OUTPUT, _ = packed_layout(ServoOutput)


def surface_value(cmd: ActuatorCommand, surface: str) -> float:
    """The command for a surface by name; ``flaps`` is aux[0], ``brakes`` aux[1]; other
    extras are not driven (NaN)."""
    at = SURFACE_AT.get(surface)
    return math.nan if at is None else _COMMAND.unpack_from(cmd)[at]


class MiniSscOutput(Plugin):
    """Writes changed channels first, never more than one cycle of frames ahead of the wire."""

    nice = FLIGHT_NICE
    trigger = "control/actuators"
    trigger_timeout_s = WAIT_S

    settings = {
        "device": Setting(str, doc="serial:///dev/ttyS1:9600, a pty path or a pyserial URL"),
        "baud": Setting(int, 9600, "the card's jumper setting", choices=(2400, 9600)),
        "stale_s": Setting(float, 0.5, "no command for this long: safe positions", min=0.05),
        "flight_hold_s": Setting(
            float,
            2.0,
            "armed, no command for this long: safe positions; until then the last are held"
            " (a controller restarting in flight answers within it)",
            min=0.05,
        ),
    }
    optional_inputs = ("control/actuators", "control/status", "link/commands")
    outputs = ("actuators/servos", "link/command_acks")

    @classmethod
    def prearm(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[str]:
        problem = open_problem(settings["device"], settings["baud"])
        return [] if problem is None else [f"servo device: {problem}"]

    @classmethod
    def probe(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[DeviceProbe]:
        """The card only listens: it is sent every channel at its safe position (the
        vehicle's airframe says where that is)."""
        safe = load_airframe(vehicle["airframe"]).channels
        neutral = minissc.frames((c.servo, c.safe) for c in safe)
        return [DeviceProbe(settings["device"], settings["baud"], None, neutral=neutral)]

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.airframe: Airframe = load_airframe(ctx.vehicle["airframe"])
        self.port = ReopeningSerial(ctx.settings["device"], ctx.settings["baud"])
        self.per_second = minissc.frames_per_second(ctx.settings["baud"])
        # The reader before the writer: the controller takes this writer as the sign that
        # its commands are heard (control.fixed_wing waits for it before its first one).
        self.commands = ctx.bus.queue_reader("control/actuators")
        self.waiter = ctx.bus.waiter([self.commands])
        self.out = ctx.bus.writer("actuators/servos")
        self.requests = ctx.bus.queue_reader("link/commands")  # DO_SET_SERVO's
        self.acks = ctx.bus.writer("link/command_acks")
        self.spare: dict[int, int] = {}  # spare outputs set by DO_SET_SERVO: servo, position
        self.safe = {c.servo: c.safe for c in self.airframe.channels}
        self.wanted = dict(self.safe)
        self.sent: dict[int, int] = {}
        self.refresh_order = [c.servo for c in self.airframe.channels]
        # Each channel with where its command is (None: not driven), chosen once.
        self.readers = [(c, SURFACE_AT.get(c.surface)) for c in self.airframe.channels]
        self.last_command_at: float | None = None  # vehicle seconds
        self.cycle_s = CYCLE_MAX_S
        self.stale = True
        self.flying = False  # the last command was armed
        self.trim = FlyingTrim()  # what the surfaces flew on lately
        self.held_mark = Path(ctx.vehicle.get("state_dir", ".")) / f"{ctx.name}_held_in_flight"
        if self._started_in_flight(ctx):
            ctx.log.warning("started in flight: the card holds its positions until a command")
            self.flying, self.stale = True, False  # stale after flight_hold_s without one
        # Every channel safe at once, so the first command finds the same card every time.
        elif self._send(len(self.safe)):
            self._publish(-1)

    def _started_in_flight(self, ctx: PluginContext) -> bool:
        """Whether the aircraft may be in the air: the controller's last status says it is
        not landed, or the last servo process trimmed the card as its supervisor died."""
        status = ctx.bus.latest_reader("control/status").get()
        try:
            age_s = time.time() - self.held_mark.stat().st_mtime
            self.held_mark.unlink()
        except OSError:
            age_s = math.inf
        return (status is not None and not status.landed) or 0 <= age_s < HELD_MARK_MAX_S

    def step(self) -> None:
        self.waiter.sleep(WAIT_S)  # the waiter counts its own idle time; the commands are read
        for request in self.requests.pending():
            if request.command == CommandId.SET_SERVO:
                self._set_servo(request)
        received = self.commands.pending()
        # The wire runs on vehicle time: in a simulation, simulated seconds.
        now = self.ctx.clock.now_us() / 1e6
        if received:
            # A command is no older than its own stamp. A plug-in started in a simulation
            # held for its answer reads time 0 until the simulator's next frame: taken as
            # the command's time, the next wake-up (a wall-clock timeout, or not, as the
            # machine ran) found it seconds old and sent safe positions for a frame.
            command = _COMMAND.unpack_from(received[-1])
            now = max(now, command[0] / 1e6)
            if self.last_command_at is not None:
                gap = now - self.last_command_at
                self.cycle_s = min(CYCLE_MAX_S, max(CYCLE_MIN_S, gap))
            self.last_command_at = now
            self.wanted = self._positions(command)
            self.stale = False
            self.flying = bool(command[_ARMED])
            if self.flying:
                self.trim.update(self.wanted, now)
        elif self.last_command_at is None and not self.stale:
            # Started in flight: held from the first wake-up that knows the time (a held
            # simulation reads 0 until its next frame).
            self.last_command_at = now if now > 0 else None
        elif (
            not self.stale
            and self.last_command_at is not None
            and now - self.last_command_at > self._stale_after_s()
        ):
            self.ctx.log.warning(
                "no command for %.2f s: safe positions", now - self.last_command_at
            )
            self.wanted, self.stale = dict(self.safe), True
        if not received and not self.stale:
            return  # refreshes ride on the commands' cycles, not on wall-clock timeouts
        if self._send(self._room()) or received:
            # Also when nothing changed: a lockstep simulator waits for this answer.
            self._publish(received[-1].t_us if received else -1)

    def close(self) -> None:
        if self.ctx.supervisor_gone():
            # The execution control crashed, maybe in the air: throttle off would drop the
            # aircraft while the vehicle restarts, and a held roll would roll it over. The
            # card holds the surfaces at the trim they flew on lately and the last throttle
            # until the restarted vehicle's controller commands it again.
            self.ctx.log.warning("the supervisor is gone: surfaces trimmed, throttle held")
            trimmed = [c.servo for c in self.airframe.channels if c.surface in FLIGHT_SURFACES]
            self.wanted.update({s: self.trim.position(s, self.safe[s]) for s in trimmed})
            for servo in trimmed:
                self.sent.pop(servo, None)  # sent again, whatever the card had
            if self._send(len(trimmed)):
                self._mark_held()
        else:
            self.wanted = dict(self.safe)
            self.sent = {}  # everything counts as changed: all channels go out
            if self._send(len(self.safe)):
                self._publish(-1)
        self.waiter.close()
        self.port.close()

    def _mark_held(self) -> None:
        """Tell the restarted vehicle's servo plug-in that the card was left flying."""
        try:
            atomic_write_text(self.held_mark, "trimmed as the supervisor died\n")
        except OSError as exc:
            self.ctx.log.warning("could not leave %s: %s", self.held_mark, exc)

    def _stale_after_s(self) -> float:
        """Armed, throttle off and trimmed surfaces would put the aircraft into a glide or a
        dive while its controller restarts: the last positions are held for longer."""
        settings = self.ctx.settings
        return (
            max(settings["stale_s"], settings["flight_hold_s"])
            if self.flying
            else settings["stale_s"]
        )

    def _positions(self, command: tuple[float, ...]) -> dict[int, int]:
        """Each channel's position for a command (``_COMMAND``'s fields)."""
        if not command[_ARMED]:
            return dict(self.safe)
        positions = {}
        for c, at in self.readers:
            value = math.nan if at is None else command[at]
            if math.isfinite(value):
                positions[c.servo] = c.position(value)
            else:  # a broken command: this surface holds its last good position
                self.ctx.health.refused += 1
                positions[c.servo] = self.wanted.get(c.servo, self.safe[c.servo])
        positions.update(self.spare)
        return positions

    def _set_servo(self, request: VehicleCommand) -> None:
        """DO_SET_SERVO on a spare output (the link has checked the output and the pulse
        are in range); answered, with the reason when refused."""
        output, pulse = round(request.param[0]), round(request.param[1])
        servo = output - 1
        surface = next((c.surface for c in self.airframe.channels if c.servo == servo), None)
        result, reason = CommandResult.ACCEPTED, ""
        if surface is not None or servo not in SERVO_IDS:
            why = f"drives the {surface}" if surface else "is not one of the card's 8"
            result, reason = CommandResult.DENIED, f"Set servo: output {output} {why}"
        else:
            position = minissc.position_for_pulse(pulse)
            self.spare[servo] = self.wanted[servo] = position
            if servo not in self.refresh_order:
                self.refresh_order.append(servo)
            # A camera's pulses, two a photo, are the controller's to tell ("photo N at").
            say = self.ctx.log.debug if request.seq == CAMERA_SEQ else self.ctx.log.info
            say("output %d (servo %d) set to %d us", output, servo, pulse)
        source, now = self.ctx.name.encode(), self.ctx.clock.now_us()
        self.acks.publish(CommandAck.answer(request, now, source, result, reason))

    def _room(self) -> int:
        """Frames that fit in one cycle, less what is still queued for the wire."""
        cycle_frames = max(1, int(self.per_second * self.cycle_s))
        return cycle_frames - self.port.out_waiting() // FRAME_BYTES

    def _send(self, room: int) -> bool:
        """Write the next frames; whether any went out."""
        plan = minissc.plan_cycle(self.wanted, self.sent, self.refresh_order, room)
        if not plan:
            return False
        data = minissc.frames(plan)
        if self.port.write(data) != len(data):
            self.ctx.health.bad()
            return False
        self.ctx.health.ok(len(plan))
        self.sent.update(plan)
        # The channels just sent go to the back of the refresh order, in the order sent.
        planned = [servo for servo, _ in plan]
        self.refresh_order = [s for s in self.refresh_order if s not in planned] + planned
        return True

    def _publish(self, command_t_us: int) -> None:
        positions, pulses, table = [0] * 8, [0] * 8, minissc.PULSES_US
        for servo, position in self.sent.items():
            # Masked as the message's uint8 and uint16 fields keep them.
            positions[servo] = position & 0xFF
            pulse = table[position] if 0 <= position < len(table) else minissc.pulse_us(position)
            pulses[servo] = pulse & 0xFFFF
        packed = _OUTPUT.pack(self.ctx.clock.now_us(), *pulses, *positions, command_t_us,
                              self.port.bytes_out)  # fmt: skip
        self.out.publish(ServoOutput.from_buffer_copy(packed))
