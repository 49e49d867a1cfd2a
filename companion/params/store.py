"""The parameter store: declarations merged from their owners, values checked and kept.

Every value is a float on the wire (MAV_PARAM_TYPE_REAL32, the one encoding QGroundControl,
MAVSDK and MAVProxy agree on). A set outside a parameter's range is refused and the old
value kept. Values persist atomically as JSON and are restored at start; a stored value
that no longer fits its declaration, or a corrupt file, is logged and ignored.
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from companion.params.atomic import atomic_write_text

log = logging.getLogger(__name__)
MAX_NAME = 16


class ParamError(ValueError):
    """A declaration or a value the store refuses."""


@dataclass(frozen=True)
class ParamDecl:
    """One parameter as its owner declares it."""

    name: str
    default: float
    min: float = -math.inf
    max: float = math.inf
    unit: str = ""
    doc: str = ""
    reboot_required: bool = False

    def check(self, value: float) -> str | None:
        """Why ``value`` is not acceptable, or None."""
        if not math.isfinite(value):
            return f"{self.name}: {value} is not a finite number"
        if value < self.min or value > self.max:
            return f"{self.name}: {value:g} outside [{self.min:g}, {self.max:g}]"
        return None


class ParamStore:
    """All parameters of the vehicle, in a fixed order (the index QGroundControl uses)."""

    def __init__(self, decls: Iterable[ParamDecl], path: Path | None = None) -> None:
        self.decls: dict[str, ParamDecl] = {}
        for decl in decls:
            if len(decl.name) > MAX_NAME or not decl.name:
                raise ParamError(f"parameter name {decl.name!r} must be 1-{MAX_NAME} characters")
            if decl.name in self.decls:
                raise ParamError(f"parameter {decl.name} declared twice")
            if (problem := decl.check(decl.default)) is not None:
                raise ParamError(f"default of {problem}")
            self.decls[decl.name] = decl
        self.names = sorted(self.decls)
        self.values = {name: float(d.default) for name, d in self.decls.items()}
        self.path = path
        if path is not None:
            self._restore(path)

    def __len__(self) -> int:
        return len(self.names)

    def get(self, name: str) -> float:
        return self.values[name]

    def index_of(self, name: str) -> int:
        return self.names.index(name)

    def set(self, name: str, value: float) -> float:
        """Set and persist; ParamError (old value kept) when unknown or out of range."""
        decl = self.decls.get(name)
        if decl is None:
            raise ParamError(f"unknown parameter {name!r}")
        if (problem := decl.check(float(value))) is not None:
            raise ParamError(problem)
        self.values[name] = float(value)
        self.save()
        return self.values[name]

    def save(self) -> None:
        if self.path is not None:
            atomic_write_text(self.path, json.dumps(self.values, indent=1, sort_keys=True))

    def _restore(self, path: Path) -> None:
        try:
            stored = json.loads(path.read_text())
        except FileNotFoundError:
            return
        except (OSError, ValueError) as exc:
            log.warning("parameter file %s unreadable (%s): using defaults", path, exc)
            return
        if not isinstance(stored, dict):
            log.warning("parameter file %s is not a table: using defaults", path)
            return
        for name, value in stored.items():
            decl = self.decls.get(name)
            if decl is None or not isinstance(value, int | float):
                log.warning("parameter file %s: ignoring %s = %r", path, name, value)
                continue
            if (problem := decl.check(float(value))) is not None:
                log.warning("parameter file %s: ignoring %s", path, problem)
                continue
            self.values[name] = float(value)
