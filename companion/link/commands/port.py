"""What a command handler may do to the vehicle: the link's small interface to it."""

from __future__ import annotations

from typing import Any, Protocol

from companion.link.codec import dialect as d
from companion.link.command_service import CommandService, Outcome
from companion.link.snapshot import Snapshot
from companion.messages import PluginState

# How long a command handed to another plug-in waits for its answer: a busy machine may
# take seconds to start the flight group.
BUS_ACK_TIMEOUT_S = 10.0


class VehiclePort(Protocol):
    """The vehicle as command handlers see it (the link plug-in provides it)."""

    snapshot: Snapshot  # the newest bus values, refreshed every step

    def publish_command(
        self, command: int, params: tuple[float, ...] = (), to: bytes | None = None
    ) -> int:
        """Put a VehicleCommand on the bus (for the flight plug-in of kind ``to``: once it
        listens, ``commands.held``); returns the sequence its ack will carry."""
        ...

    def statustext(self, text: str, severity: int = d.MAV_SEVERITY_WARNING) -> None:
        """Tell every ground station."""
        ...

    def has_commander(self) -> bool:
        """Whether a commander plug-in is there to answer mode commands."""
        ...

    def param(self, name: str) -> float:
        """The current value of one of the link's own parameters."""
        ...

    def open_imu(self) -> Any:
        """A reader of every IMU sample from now on (``drain()``, ``close()``), for a sensor
        calibration: the telemetry reads only the newest."""
        ...

    def prearm_failures(self) -> list[str]:
        """Why arming would be refused now (companion.control.prearm; empty: ready)."""
        ...

    @property
    def simulated(self) -> bool:
        """Whether the vehicle runs on the simulator's clock."""
        ...


def refuse(port: VehiclePort, service: CommandService | None, text: str) -> Outcome:
    """DENIED, said and counted as a broken parameter rule is (at most a few texts a
    second: a flood of refused commands must not flood every link with texts)."""
    if service is None:
        port.statustext(text)
    else:
        service.refused += 1
        service.on_refusal(text)
    return Outcome(d.MAV_RESULT_DENIED)


def flying(port: VehiclePort) -> bool:
    """Whether the flight controller runs and says the aircraft is off the ground."""
    control = port.snapshot.control
    return control is not None and not control.landed


def armed(port: VehiclePort) -> bool:
    """Whether the flight plug-ins run, as the newest health table says."""
    health = port.snapshot.health
    return health is not None and bool(health.flight_running)


def plugin_running(port: VehiclePort, kind: bytes) -> bool:
    """Whether the health table shows a plug-in of ``kind`` (``b"actuators.minissc"``)
    running: one of the flight group runs only while armed."""
    health = port.snapshot.health
    row = health.row_of_kind(kind) if health is not None else None
    return row is not None and row.state == PluginState.RUNNING
