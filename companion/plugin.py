"""The plug-in contract: what every plug-in is given and what it must provide.

A plug-in is the thesis's shared library run in its own process: ``init(ctx)`` once,
then ``step()`` over and over (each call blocks on the plug-in's inputs or device and
returns after one unit of work), then ``close()``. It talks only to the bus and its own
device. The execution control finds a plug-in by the name in the config: a registered
short name (entry-point group ``companion.plugins``) or ``"package.module:ClassName"``.
"""

from __future__ import annotations

import logging
import os
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar, Protocol

if TYPE_CHECKING:
    from companion.bus.clock import VehicleClock
    from companion.bus.node import BusNode
    from companion.params import ParamDecl

REQUIRED: Any = object()
# The classmethods below get the config's [vehicle] table beside the plug-in's settings:
# what belongs to the whole vehicle (its airframe) is named once, there.
NO_VEHICLE: Mapping[str, Any] = MappingProxyType({})


@dataclass(frozen=True)
class Setting:
    """One declared setting of a plug-in: its type, default and meaning."""

    type: type
    default: Any = REQUIRED
    doc: str = ""
    choices: tuple[Any, ...] | None = None
    min: float | None = None
    max: float | None = None

    @property
    def required(self) -> bool:
        """True when the config must give a value."""
        return self.default is REQUIRED


@dataclass(frozen=True)
class Ports:
    """The bus channels a plug-in instance reads and writes (checked before start)."""

    inputs: tuple[str, ...] = ()  # channels that must have a producer
    optional_inputs: tuple[str, ...] = ()  # read when present (e.g. telemetry for the link)
    outputs: tuple[str, ...] = ()


class ProbeStream(Protocol):
    """A device's bytes decoded as its plug-in decodes them, counted (``companion check``)."""

    @property
    def frames_ok(self) -> int:
        """Frames (sentences) the plug-in's decoder accepted."""
        ...

    @property
    def frames_bad(self) -> int:
        """Frames refused: bad checksums, undecodable frames, stretches of garbage."""
        ...

    def feed(self, data: bytes, t_us: int) -> list[Any]:
        """The readings completed by ``data``."""
        ...


@dataclass
class DeviceProbe:
    """One device of a plug-in as ``companion check`` tries it on the bench."""

    device: str  # as the config gives it: a path, serial://PATH:BAUD or a pyserial URL
    baud: int
    stream: ProbeStream | None  # None: a device the vehicle only writes to
    rate_hz: float = 0.0  # readings a second a healthy device sends (0: not known)
    text: bool = False  # it speaks printable text (garbage is then told from a wrong baud)
    framing: Mapping[str, Any] = field(default_factory=dict)  # pyserial's, when not 8N1
    neutral: bytes = b""  # what a write-only device is sent: every output at its safe place
    must_answer: bool = True  # False: silence is normal (a radio with no station on)
    what: str = ""  # which of the plug-in's devices, when it has several


@dataclass
class HealthCounters:
    """Counters every plug-in keeps; the runner publishes them on system/plugin_stats."""

    frames_ok: int = 0
    frames_bad: int = 0
    dropped: int = 0
    refused: int = 0  # well-formed input refused by its rules (NaN, out of range)
    bytes_in: int = 0  # read from the plug-in's device (pre-arm tells silence from garbage)
    # When the runner last published them: a reading counted in a report must not be
    # stamped after it, nor one counted later before it (serial_sensor's spread stamps).
    reported_us: int | None = None

    def ok(self, n: int = 1) -> None:
        """Count good frames (or samples) accepted."""
        self.frames_ok += n

    def bad(self, n: int = 1) -> None:
        """Count rejected frames: bad checksums, garbage, invalid values."""
        self.frames_bad += n


@dataclass
class PluginContext:
    """Everything a plug-in gets from the execution control."""

    name: str  # the instance name from the config
    settings: Mapping[str, Any]  # validated, defaults filled in
    log: logging.Logger
    bus: BusNode
    clock: VehicleClock
    vehicle: Mapping[str, Any] = field(default_factory=dict)  # the config's [vehicle] table
    health: HealthCounters = field(default_factory=HealthCounters)
    # Every parameter declared by the config's plug-ins (what the parameter server serves);
    # only for a plug-in whose class sets wants_vehicle_tables, empty for the others.
    param_decls: tuple[ParamDecl, ...] = ()
    # Every plug-in's validated settings by plug-in kind (the flight log records the
    # navigator's, so a replay runs it as it flew); as param_decls, only when wanted.
    plugins: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    # Readable once a signal (a stop request) has come: a plug-in that waits on a device
    # rather than on the bus polls it too (ReopeningSerial's stop_fd), so a long timeout
    # still lets it stop at once. None where nobody set one up (a plug-in built in a test).
    stop_fd: int | None = None
    # The execution control's process id, as this process started. None outside one.
    supervisor_pid: int | None = None

    def supervisor_gone(self) -> bool:
        """Whether the execution control died under this process (killed, crashed): its
        orphaned plug-ins stop, and a restarted vehicle takes over their devices."""
        return self.supervisor_pid is not None and os.getppid() != self.supervisor_pid


# Raising a priority needs CAP_SYS_NICE (root, or the service unit's capability); without
# it a plug-in runs at the supervisor's (companion.exec_control.priority).
FLIGHT_NICE = -5


class Plugin(ABC):
    """Base class of every plug-in.

    Subclasses declare ``settings`` (name → Setting), and their bus channels either as the
    class attributes ``inputs``/``optional_inputs``/``outputs`` or, when they depend on the
    settings, by overriding ``ports()``.
    """

    settings: ClassVar[dict[str, Setting]] = {}
    params: ClassVar[tuple[ParamDecl, ...]] = ()  # served to ground stations by the link
    inputs: ClassVar[tuple[str, ...]] = ()
    optional_inputs: ClassVar[tuple[str, ...]] = ()
    outputs: ClassVar[tuple[str, ...]] = ()
    # Whether ctx.param_decls and ctx.plugins hold every plug-in's parameters and settings
    # (the link serves them, the flight logger records them). Other plug-ins get them
    # empty: parsing them cost each plug-in process ~1 MB of its own memory.
    wants_vehicle_tables: ClassVar[bool] = False
    # The Linux nice value its process asks for (the config's ``nice`` overrides it). The
    # IMU -> navigator -> controller -> servos chain and the pilot's receiver ask for
    # FLIGHT_NICE: on a board short of CPU the link, the flight log and the slower sensors
    # give way to them, not the other way round. Other work on the board keeps nice 0.
    nice: ClassVar[int] = 0
    # The input whose every sample starts a step (the navigator's IMU, the controller's
    # navigation state), if there is one. When the config places the plug-in in the same
    # process as the plug-in that publishes it, the process runs this one right after that
    # one's step that published, on the same wake-up (docs/dev/process_model.md). The
    # plug-in's code is the same either way: its wait then finds the sample already there.
    trigger: ClassVar[str | None] = None
    # How long its step waits for the trigger before going on without one (its timeouts:
    # the servos' safe positions when commands stop). Chained, and not run by its producer
    # for this long, it is stepped by a thread of its own meanwhile.
    trigger_timeout_s: ClassVar[float] = 0.1

    @classmethod
    def ports(cls, settings: Mapping[str, Any]) -> Ports:
        """The channels this instance will read and write, given its settings."""
        return Ports(cls.inputs, cls.optional_inputs, cls.outputs)

    @classmethod
    def param_decls(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> tuple[ParamDecl, ...]:
        """The parameters this instance serves (``params``, unless they depend on settings)."""
        return tuple(cls.params)

    @classmethod
    def validate(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[str]:
        """Problems with the settings taken together (checked before anything starts)."""
        return []

    @classmethod
    def prearm(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[str]:
        """Why this ``flight`` plug-in could not fly now (its device missing...), checked by
        the supervisor before arming; each reason follows ``PreArm: ``."""
        return []

    @classmethod
    def probe(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[DeviceProbe]:
        """The devices ``companion check`` opens on the bench, each with this plug-in's own
        decoder (none: the plug-in has no device)."""
        return []

    @classmethod
    def bench_problems(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[str]:
        """What ``companion check`` finds wrong on this machine besides the devices (a key
        file missing...); the config check cannot know, it may run on another computer."""
        return []

    def init(self, ctx: PluginContext) -> None:
        """Open the device and the bus ports. Raising here counts as a crash."""
        self.ctx = ctx

    @abstractmethod
    def step(self) -> None:
        """Block on inputs (at most about half a second) and do one unit of work."""

    def close(self) -> None:  # noqa: B027 - optional hook, empty by design
        """Release the device. Bus ports are released by the runner."""
