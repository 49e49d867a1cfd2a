"""A VehiclePort for the link's command groups in process: it records what they did."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from companion.link.codec import new_encoder
from companion.link.command_rules import RULES, refusal
from companion.link.command_service import CommandService
from companion.link.snapshot import Snapshot
from companion.messages import PluginState, SystemHealth


@dataclass
class SampleFeed:
    """What ``open_imu`` gives: the samples a test puts in ``pending``, each drained once."""

    pending: list[Any] = field(default_factory=list)
    closed: bool = False

    def drain(self) -> list[Any]:
        out, self.pending = self.pending, []
        return out

    def close(self) -> None:
        self.closed = True


@dataclass
class RecordingVehicle:
    """A VehiclePort that keeps what the handlers did (the bus side is the link's own)."""

    snapshot: Snapshot = field(default_factory=Snapshot)
    commander: bool = True
    # The defaults of the parameters the command groups read, as the link declares them.
    params: dict[str, float] = field(
        default_factory=lambda: {"SYS_FAILURE_EN": 0.0, "ARMING_CHECK": 1.0}
    )
    simulated: bool = True
    published: list[tuple[int, tuple[float, ...]]] = field(default_factory=list)
    published_to: list[bytes | None] = field(default_factory=list)  # each one's plug-in
    texts: list[str] = field(default_factory=list)
    feeds: list[SampleFeed] = field(default_factory=list)  # one per open_imu
    prearm: list[str] = field(default_factory=list)  # what prearm_failures reports

    def publish_command(
        self, command: int, params: tuple[float, ...] = (), to: bytes | None = None
    ) -> int:
        self.published.append((command, tuple(params)))
        self.published_to.append(to)
        return len(self.published)

    def statustext(self, text: str, severity: int = 4) -> None:
        self.texts.append(text)

    def has_commander(self) -> bool:
        return self.commander

    def param(self, name: str) -> float:
        return self.params[name]

    def prearm_failures(self) -> list[str]:
        return list(self.prearm)

    def open_imu(self) -> SampleFeed:
        self.feeds.append(SampleFeed())
        return self.feeds[-1]


def command_bench(
    register: Callable[[RecordingVehicle], Any], kind: bytes, running: bool
) -> tuple[CommandService, RecordingVehicle]:
    """A command service behind the parameter rules, with the command group ``register``
    makes of the vehicle (``lambda v: CameraCommands(v)``) registered; the health table
    shows the plug-in of ``kind`` running (armed) or stopped."""
    service = CommandService(new_encoder(1, 1), 1, 1)
    service.guard(refusal, RULES)
    vehicle = RecordingVehicle()
    service.on_refusal = vehicle.statustext
    health = SystemHealth(count=1, flight_running=int(running))
    health.plugins[0].kind = kind
    health.plugins[0].state = int(PluginState.RUNNING if running else PluginState.STOPPED)
    vehicle.snapshot.health = health
    register(vehicle).register(service)
    return service, vehicle
