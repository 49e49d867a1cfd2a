"""What the simulator reads from an airframe file: the model to fly and the servo wiring.

The file is the one the vehicle's servo output uses (``companion/airframes/*.toml``);
the simulator reads it on its own so that a mistake in the vehicle's reading shows up as
a surface that moves the wrong way rather than cancelling out. It needs:

- ``[airframe]``: ``jsbsim_model`` (the file's stem if absent) and ``cruise_speed_m_s``;
- ``[channels.<surface>]``: ``servo``, ``trim``, ``min``, ``max``, ``reversed``, to turn
  the position the card receives back into the surface's command.

A surface's command is -1 at ``min``, 0 at ``trim``, +1 at ``max`` (each half of the travel
scaled on its own), negated when reversed. ``throttle`` runs 0 at ``min`` to 1 at ``max``
(``max`` to ``min`` when reversed). Positions outside the travel count as its end.
"""

from __future__ import annotations

import importlib.resources
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

FULL_TRAVEL = (0, 254)  # Mini SSC positions; 255 is the sync byte
CENTRE = 127
THROTTLES = frozenset({"throttle", "brakes"})  # one-sided: command 0 at the bottom


@dataclass(frozen=True)
class SurfaceServo:
    """One servo as the flight model sees it: its travel in Mini SSC positions."""

    surface: str
    bottom: int  # the file's min
    trim: int  # command 0 of a surface; a throttle's is its bottom
    top: int  # the file's max
    reversed: bool

    def command(self, position: int) -> float:
        """The normalised command a received position stands for."""
        position = min(self.top, max(self.bottom, position))
        if self.surface in THROTTLES:
            travel = self.top - self.bottom
            if travel == 0:
                return 0.0
            up = self.top - position if self.reversed else position - self.bottom
            return up / travel
        half = self.top - self.trim if position >= self.trim else self.trim - self.bottom
        deflection = 0.0 if half == 0 else (position - self.trim) / half
        return -deflection if self.reversed else deflection


@dataclass(frozen=True)
class SimAirframe:
    """The airframe file as the simulator needs it."""

    jsbsim_model: str
    cruise_speed_m_s: float
    servos: dict[int, SurfaceServo]  # by Mini SSC servo number


def airframe_file(name_or_path: str) -> Path:
    """A TOML path as given, or the shipped airframe of that name."""
    path = Path(name_or_path)
    if path.suffix == ".toml" or path.exists():
        return path
    shipped = importlib.resources.files("companion") / "airframes" / f"{name_or_path}.toml"
    return Path(str(shipped))


def read_airframe(name_or_path: str) -> SimAirframe:
    """Read the file; ValueError names the file and the key that is missing or wrong."""
    path = airframe_file(name_or_path)
    try:
        data = tomllib.loads(path.read_text())
        head = data["airframe"]
        servos = {}
        for surface, spec in data.get("channels", {}).items():
            servo = _surface_servo(surface, spec)
            servos[int(spec["servo"])] = servo
        return SimAirframe(
            jsbsim_model=str(head.get("jsbsim_model", path.stem)),
            cruise_speed_m_s=float(head["cruise_speed_m_s"]),
            servos=servos,
        )
    except (OSError, tomllib.TOMLDecodeError, KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"airframe {path}: {exc!r}") from None


def _surface_servo(surface: str, spec: dict[str, Any]) -> SurfaceServo:
    bottom = int(spec.get("min", FULL_TRAVEL[0]))
    top = int(spec.get("max", FULL_TRAVEL[1]))
    if surface == "brakes":  # held at trim (full unless less is given) until commanded
        trim = int(spec.get("trim", top))
    else:
        trim = bottom if surface in THROTTLES else int(spec.get("trim", CENTRE))
    if not FULL_TRAVEL[0] <= bottom <= trim <= top <= FULL_TRAVEL[1]:
        raise ValueError(f"[channels.{surface}]: need 0 <= min <= trim <= max <= 254")
    return SurfaceServo(surface, bottom, trim, top, bool(spec.get("reversed", False)))
