"""The simulator's side of ``link/commands``: what it answers, what it follows, what it sends.

- It answers failure injection (``INJECT_FAILURE``) on its emulated devices.
- It follows START (its acknowledgement) and STOP, so lockstep with the control loop knows
  when the flight plug-ins run.
- With ``start_at_s`` it arms the vehicle and starts its mission itself at that simulated
  second, holding the simulation until each is acknowledged: the flight then begins at
  the same frame every run, which a ground station's command (sent in wall time) cannot
  promise.
- With ``hold_at_s`` it holds the simulation at that simulated second until a ground
  station has armed the vehicle and started its mission (both acknowledged as accepted):
  a flight flown by a person's or a script's clicks then also begins at the same frame.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

from bridges.jsbsim.failures import DeviceFailures
from companion.messages import CommandAck, CommandId, CommandResult, VehicleCommand

if TYPE_CHECKING:
    from bridges.jsbsim.lockstep import FlightSync
    from companion.bus.node import BusNode

log = logging.getLogger(__name__)

SEQ_BASE = 1 << 31  # the bridge's own command numbers, apart from the link's
ACK_TIMEOUT_S = 10.0
POLL_S = 1e-3
HELD_UPDATE_S = 0.05  # while held: how often late readers are handed the clock


class VehicleCommands:
    """Reads ``link/commands`` and ``link/command_acks`` once a frame."""

    def __init__(
        self,
        bus: BusNode,
        failures: DeviceFailures,
        sync: FlightSync | None,
        start_at_s: float | None = None,
        navigated: FlightSync | None = None,
        hold_at_s: float | None = None,
    ) -> None:
        self.commands = bus.queue_reader("link/commands")
        self.acks_in = bus.queue_reader("link/command_acks")
        self.out = bus.writer("link/commands")
        self.acks = bus.writer("link/command_acks")
        self.failures, self.sync = failures, sync
        self.navigated = navigated  # the navigator's answers, waited for before arming
        self.start_at_s, self.hold_at_s = start_at_s, hold_at_s
        self.seq = SEQ_BASE
        self.answers: dict[int, int] = {}  # our seq → result
        self.accepted: set[int] = set()  # START and MISSION_START, once acknowledged so
        self.cancelled = False  # the simulation is ending: hold no longer
        # Called while held: the bridge hands its clock to readers that joined meanwhile
        # (the flight plug-ins the arming starts would read simulation time 0 otherwise).
        self.on_hold: Callable[[], None] | None = None

    def serve(self, t_us: int) -> bool:
        """Take what arrived; at ``start_at_s``, arm and start the mission; at
        ``hold_at_s``, hold until a ground station has. Whether the simulation was held."""
        self._take_acks()
        self._take_commands(t_us)
        if self.start_at_s is not None and t_us >= self.start_at_s * 1e6:
            self.start_at_s = None
            self._this_frames_solution(t_us)
            for command in (CommandId.START, CommandId.MISSION_START):
                if not self._send(command, t_us):
                    break
            return True
        if self.hold_at_s is not None and t_us >= self.hold_at_s * 1e6:
            self.hold_at_s = None
            self._this_frames_solution(t_us)
            self._hold(t_us)
            return True
        return False

    def _this_frames_solution(self, t_us: int) -> None:
        if self.navigated is not None:
            # Arming sets home where the navigator says the aircraft is: from this
            # frame's solution, not whichever one the navigator had finished by then.
            self.navigated.wait(t_us)

    def _take_commands(self, t_us: int) -> None:
        for cmd in self.commands.drain():
            if cmd.command == CommandId.STOP:
                self.accepted.discard(CommandId.START)
                if self.sync is not None:
                    self.sync.started(False)
            if cmd.command == CommandId.INJECT_FAILURE:
                self._inject(cmd, t_us)

    def _hold(self, t_us: int) -> None:
        """Hold until START and MISSION_START have been accepted (or the run ends)."""
        wanted = {CommandId.START, CommandId.MISSION_START}
        log.warning(
            "holding the simulation at %.1f s until the vehicle is armed and its mission started",
            t_us / 1e6,
        )
        started, handed = time.monotonic(), 0.0
        while not wanted <= self.accepted and not self.cancelled:
            time.sleep(POLL_S)
            self._take_acks()
            self._take_commands(t_us)
            if self.on_hold is not None and time.monotonic() - handed >= HELD_UPDATE_S:
                self.on_hold()
                handed = time.monotonic()
        log.info("held at %.1f s for %.1f s wall", t_us / 1e6, time.monotonic() - started)

    def _inject(self, cmd: VehicleCommand, t_us: int) -> None:
        unit, failure_type, instance = (round(v) for v in cmd.param[:3])
        result = self.failures.inject(unit, failure_type, instance)
        self.acks.publish(CommandAck.answer(cmd, t_us, b"sim_bridge", result))

    def _take_acks(self) -> None:
        for ack in self.acks_in.drain():
            if ack.seq >= SEQ_BASE:
                self.answers[int(ack.seq)] = int(ack.result)
            if ack.result != CommandResult.ACCEPTED:
                continue
            if ack.command in (CommandId.START, CommandId.MISSION_START):
                self.accepted.add(ack.command)
            if ack.command == CommandId.START and self.sync is not None:
                self.sync.started(True)

    def _send(self, command: CommandId, t_us: int) -> bool:
        """Publish a command and hold until it is acknowledged; whether it was accepted."""
        self.seq += 1
        seq = self.seq
        self.out.publish(VehicleCommand(t_us=t_us, seq=seq, command=command, source_sysid=0))
        deadline = time.monotonic() + ACK_TIMEOUT_S
        while seq not in self.answers and time.monotonic() < deadline:
            time.sleep(POLL_S)
            self._take_acks()
        result = self.answers.pop(seq, None)
        if result != CommandResult.ACCEPTED:
            what = "no answer" if result is None else CommandResult(result).name
            log.error("start at %.1f s: %s refused (%s)", t_us / 1e6, command.name, what)
            return False
        log.info("start at %.1f s: %s accepted", t_us / 1e6, command.name)
        return True
