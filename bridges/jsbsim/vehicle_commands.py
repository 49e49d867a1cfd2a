"""The simulator's side of ``link/commands``: what it answers, what it follows, what it sends.

- It answers failure injection (``INJECT_FAILURE``) on its emulated devices.
- It follows START (its acknowledgement) and STOP, so lockstep with the control loop knows
  when the flight plug-ins run.
- With ``start_at_s`` it arms the vehicle and starts its mission itself at that simulated
  second, holding the simulation until each is acknowledged: the flight then begins at
  the same frame every run, which a ground station's command (sent in wall time) cannot
  promise.
"""

from __future__ import annotations

import logging
import time
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


class VehicleCommands:
    """Reads ``link/commands`` and ``link/command_acks`` once a frame."""

    def __init__(
        self,
        bus: BusNode,
        failures: DeviceFailures,
        sync: FlightSync | None,
        start_at_s: float | None = None,
        navigated: FlightSync | None = None,
    ) -> None:
        self.commands = bus.queue_reader("link/commands")
        self.acks_in = bus.queue_reader("link/command_acks")
        self.out = bus.writer("link/commands")
        self.acks = bus.writer("link/command_acks")
        self.failures, self.sync = failures, sync
        self.navigated = navigated  # the navigator's answers, waited for before arming
        self.start_at_s = start_at_s
        self.seq = SEQ_BASE
        self.answers: dict[int, int] = {}  # our seq → result

    def serve(self, t_us: int) -> None:
        """Take what arrived; at ``start_at_s``, arm and start the mission."""
        self._take_acks()
        for cmd in self.commands.drain():
            if cmd.command == CommandId.STOP and self.sync is not None:
                self.sync.started(False)
            if cmd.command == CommandId.INJECT_FAILURE:
                self._inject(cmd, t_us)
        if self.start_at_s is not None and t_us >= self.start_at_s * 1e6:
            self.start_at_s = None
            if self.navigated is not None:
                # Arming sets home where the navigator says the aircraft is: from this
                # frame's solution, not whichever one the navigator had finished by then.
                self.navigated.wait(t_us)
            for command in (CommandId.START, CommandId.MISSION_START):
                if not self._send(command, t_us):
                    break

    def _inject(self, cmd: VehicleCommand, t_us: int) -> None:
        unit, failure_type, instance = (round(v) for v in cmd.param[:3])
        ack = CommandAck(t_us=t_us, seq=cmd.seq, command=cmd.command)
        ack.result = int(self.failures.inject(unit, failure_type, instance))
        ack.source = b"sim_bridge"
        self.acks.publish(ack)

    def _take_acks(self) -> None:
        for ack in self.acks_in.drain():
            if ack.seq >= SEQ_BASE:
                self.answers[int(ack.seq)] = int(ack.result)
            started = ack.command == CommandId.START and ack.result == CommandResult.ACCEPTED
            if started and self.sync is not None:
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
