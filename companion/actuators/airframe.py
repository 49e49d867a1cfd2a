"""An airframe file: which servo moves which surface, with trim, travel and reversal.

The same file drives the Mini SSC plug-in (surface command → servo position) and the
simulator bridge (servo position → JSBSim control); the bridge reads it with its own code,
so a mistake here shows as a surface that moves the wrong way in simulation.

```toml
[airframe]
name = "c172p"
jsbsim_model = "c172p"      # the simulator's aircraft for this airframe
cruise_speed_m_s = 51.0

[channels.aileron]          # aileron, elevator, rudder, throttle, or any extra name
servo = 0                   # Mini SSC servo id 0-7
trim = 127                  # position at command 0 (surfaces) — the safe position
min = 27                    # travel limits, positions 0-254
max = 227
reversed = false
```
Surfaces take commands in [-1, 1], trim at 0, the two halves of travel scaled separately
(a trim off centre keeps full deflection on both sides). ``throttle`` takes [0, 1] from
``min`` (its safe position) to ``max``.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

POSITION_MAX = 254  # 255 is the Mini SSC sync byte
SERVO_IDS = range(8)
AIRFRAMES_DIR = Path(__file__).resolve().parent.parent / "airframes"
DEFAULT_AIRFRAME = "c172p"  # a config's [vehicle] airframe when it names none
ONE_SIDED = frozenset({"throttle", "brakes"})  # commands in [0, 1]
# A stopped vehicle holds its wheel brakes at the channel's trim (full unless the airframe
# file says less: a light tail dragger noses over on full brakes in a crosswind).
SAFE_ON = frozenset({"brakes"})


class AirframeError(ValueError):
    """An airframe file that cannot be used; the message names the file and key."""


@dataclass(frozen=True)
class ServoChannel:
    """One surface's servo: id, trim and travel in Mini SSC positions."""

    surface: str
    servo: int
    trim: int
    min: int
    max: int
    reversed: bool = False

    @cached_property  # looked at with every command, 50 times a second, and never changes
    def one_sided(self) -> bool:
        """Throttle-like: command 0 is the bottom of travel, not its middle."""
        return self.surface in ONE_SIDED

    @property
    def safe(self) -> int:
        """Where the channel goes when stopped: surfaces at trim, throttle off, brakes on."""
        return self.trim if self.surface in SAFE_ON else self.position(0.0)

    def position(self, command: float) -> int:
        """The servo position for a normalised command (clamped to the travel)."""
        if command != command:  # NaN: hold safe rather than guess
            command = 0.0
        # Clamped by comparisons, not min() and max(): the same numbers (the command is not
        # NaN here) without two calls per channel, 300 a second.
        if self.one_sided:
            c = 1.0 if command > 1.0 else (0.0 if command < 0.0 else command)
            low, high = (self.max, self.min) if self.reversed else (self.min, self.max)
            return round(low + c * (high - low))
        c = -command if self.reversed else command
        c = 1.0 if c > 1.0 else (-1.0 if c < -1.0 else c)
        span = (self.max - self.trim) if c >= 0 else (self.trim - self.min)
        return round(self.trim + c * span)

    def command(self, position: int) -> float:
        """The normalised command a servo position stands for (inverse of ``position``)."""
        position = min(self.max, max(self.min, position))
        if self.one_sided:
            low, high = (self.max, self.min) if self.reversed else (self.min, self.max)
            return 0.0 if high == low else (position - low) / (high - low)
        span = (self.max - self.trim) if position >= self.trim else (self.trim - self.min)
        c = 0.0 if span == 0 else (position - self.trim) / span
        return -c if self.reversed else c


@dataclass(frozen=True)
class Airframe:
    """The airframe file's contents."""

    name: str
    jsbsim_model: str
    cruise_speed_m_s: float
    channels: tuple[ServoChannel, ...]
    source: str = ""
    # The [control] table: flight-controller parameter defaults for this airframe (checked
    # by the controller, which knows the names).
    control: dict[str, float] = field(default_factory=dict)

    def channel(self, surface: str) -> ServoChannel | None:
        """The channel driving that surface, if the airframe has one."""
        return next((c for c in self.channels if c.surface == surface), None)


def airframe_path(name_or_path: str) -> Path:
    """A shipped airframe's file by name (``c172p``), or the given path."""
    path = Path(name_or_path)
    if path.suffix == ".toml" or path.exists():
        return path
    return AIRFRAMES_DIR / f"{name_or_path}.toml"


def shipped_airframes() -> list[str]:
    """Names of the airframes that ship with the program."""
    return sorted(p.stem for p in AIRFRAMES_DIR.glob("*.toml"))


def load_airframe(name_or_path: str) -> Airframe:
    """Read and check an airframe file; AirframeError names what is wrong and where."""
    path = airframe_path(name_or_path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise AirframeError(
            f"{path}: no such airframe file (shipped: {', '.join(shipped_airframes())})"
        ) from None
    except tomllib.TOMLDecodeError as exc:
        raise AirframeError(f"{path}: {exc}") from None
    head = data.get("airframe", {})
    channels = tuple(
        _channel(path, surface, spec) for surface, spec in data.get("channels", {}).items()
    )
    ids = [c.servo for c in channels]
    if len(set(ids)) != len(ids):
        raise AirframeError(f"{path}: [channels]: two surfaces share a servo id ({ids})")
    try:
        return Airframe(
            name=str(head.get("name", path.stem)),
            jsbsim_model=str(head.get("jsbsim_model", path.stem)),
            cruise_speed_m_s=float(head["cruise_speed_m_s"]),
            channels=channels,
            source=str(path),
            control=_control(path, data.get("control", {})),
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise AirframeError(f"{path}: [airframe]: missing or bad key {exc}") from None


def _control(path: Path, table: dict[str, Any]) -> dict[str, float]:
    out = {}
    for key, value in table.items():
        if not isinstance(value, int | float) or isinstance(value, bool):
            raise AirframeError(f"{path}: [control]: {key} must be a number, not {value!r}")
        out[key] = float(value)
    return out


def _default_trim(surface: str, spec: dict[str, Any]) -> int:
    if surface in SAFE_ON:
        return int(spec.get("max", POSITION_MAX))
    return int(spec.get("min", 0)) if surface in ONE_SIDED else 127


def _channel(path: Path, surface: str, spec: dict[str, Any]) -> ServoChannel:
    where = f"{path}: [channels.{surface}]"
    unknown = set(spec) - {"servo", "trim", "min", "max", "reversed"}
    if unknown:
        raise AirframeError(f"{where}: unknown key {sorted(unknown)[0]!r}")
    try:
        ch = ServoChannel(
            surface=surface,
            servo=int(spec["servo"]),
            trim=int(spec.get("trim", _default_trim(surface, spec))),
            min=int(spec.get("min", 0)),
            max=int(spec.get("max", POSITION_MAX)),
            reversed=bool(spec.get("reversed", False)),
        )
    except KeyError as exc:
        raise AirframeError(f"{where}: missing key {exc}") from None
    except (TypeError, ValueError) as exc:
        raise AirframeError(f"{where}: {exc}") from None
    if ch.servo not in SERVO_IDS:
        raise AirframeError(f"{where}: servo {ch.servo} is not a Mini SSC id 0-7")
    if not 0 <= ch.min <= ch.trim <= ch.max <= POSITION_MAX:
        raise AirframeError(f"{where}: need 0 <= min <= trim <= max <= {POSITION_MAX}")
    return ch
