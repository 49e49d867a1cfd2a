"""The parameter store: declarations merged from their owners, values checked and kept.

Every value is a float on the wire (MAV_PARAM_TYPE_REAL32, the one encoding QGroundControl,
MAVSDK and MAVProxy agree on). A set outside a parameter's range, or not one of its
enumerated values, is refused and the old value kept. Values persist atomically as JSON
and are restored at start; a stored value that no longer fits its declaration, or a
corrupt file, is logged and ignored. An alias (``companion.params.alias``) has no value
of its own: it is read from, and written to, the parameters it stands for.
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from companion.params.alias import Alias
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
    values: tuple[tuple[float, str], ...] = ()  # an enumeration: (value, meaning); no other
    alias: Alias | None = None  # another name for the vehicle's own parameter(s)

    def __post_init__(self) -> None:  # as JSON brings them back: lists and a table
        object.__setattr__(self, "values", tuple((float(v), str(t)) for v, t in self.values))
        if isinstance(self.alias, Mapping):
            object.__setattr__(self, "alias", Alias(**self.alias))

    @classmethod
    def fixed(
        cls, name: str, value: float, doc: str, unit: str = "", values: Any = ()
    ) -> ParamDecl:
        """A parameter that reads ``value`` and refuses any other (a fact about the vehicle
        a ground station asks for by its own name, or a term this vehicle has not got)."""
        return cls(name, value, value, value, unit, doc, values=values)

    def check(self, value: float) -> str | None:
        """Why ``value`` is not acceptable, or None."""
        if not math.isfinite(value):
            return f"{self.name}: {value} is not a finite number"
        if value < self.min or value > self.max:
            return f"{self.name}: {value:g} outside [{self.min:g}, {self.max:g}]"
        if self.values and not any(math.isclose(value, v, abs_tol=1e-6) for v, _ in self.values):
            allowed = ", ".join(f"{v:g}" for v, _ in self.values)
            return f"{self.name}: {value:g} is not one of {allowed}"
        return None


def bind(decl: ParamDecl, decls: Mapping[str, ParamDecl]) -> ParamDecl:
    """An alias as this vehicle serves it: its default (and a linear one's range) from its
    owners' declarations; a fixed fact at its own default when an owner is not there."""
    alias = decl.alias
    assert alias is not None
    missing = [s for s in alias.sources if s not in decls or decls[s].alias is not None]
    if missing:
        doc = f"{decl.doc} [fixed: no {', '.join(missing)} on this vehicle]"
        values = tuple(v for v in decl.values if v[0] == decl.default)
        fixed = {"min": decl.default, "max": decl.default, "values": values}
        return replace(decl, alias=None, doc=doc, **fixed)
    lo, hi = decl.min, decl.max
    if alias.linear_only:  # the owner's range, scaled, narrowed by the alias's
        own = decls[alias.targets[0]]
        own_lo, own_hi = sorted((own.min * alias.scale, own.max * alias.scale))
        lo, hi = max(lo, own_lo), min(hi, own_hi)
    values = tuple(v for v in decl.values if lo <= v[0] <= hi)  # only what the owner takes
    default = alias.read({name: d.default for name, d in decls.items()})
    return replace(decl, default=default, min=lo, max=hi, values=values)


class ParamStore:
    """All parameters of the vehicle, in a fixed order (the index QGroundControl uses)."""

    def __init__(
        self, decls: Iterable[ParamDecl], path: Path | None = None, partial: bool = False
    ) -> None:
        """``partial``: one owner's parameters, restored from the vehicle's shared file,
        whose other names belong to other owners (not worth a warning each)."""
        self.partial = partial
        self.decls: dict[str, ParamDecl] = {}
        for decl in decls:
            if len(decl.name) > MAX_NAME or not decl.name:
                raise ParamError(f"parameter name {decl.name!r} must be 1-{MAX_NAME} characters")
            if decl.name in self.decls:
                raise ParamError(f"parameter {decl.name} declared twice")
            self.decls[decl.name] = decl
        self.aliases: dict[str, Alias] = {}
        for name, decl in list(self.decls.items()):
            if decl.alias is not None:
                self.decls[name] = bound = bind(decl, self.decls)
                if bound.alias is not None:
                    self.aliases[name] = bound.alias
        for decl in self.decls.values():
            if (problem := decl.check(decl.default)) is not None:
                raise ParamError(f"default of {problem}")
        self.names = sorted(self.decls)
        self.values = {n: float(d.default) for n, d in self.decls.items() if n not in self.aliases}
        self.path = path
        if path is not None:
            self._restore(path)

    def __len__(self) -> int:
        return len(self.names)

    def get(self, name: str) -> float:
        alias = self.aliases.get(name)
        return self.values[name] if alias is None else alias.read(self.values)

    def index_of(self, name: str) -> int:
        return self.names.index(name)

    def plan(self, name: str, value: float) -> dict[str, float]:
        """The stored values a set would change (an alias's: its owners'); ParamError when
        unknown, out of range or not something the owners can honour."""
        decl = self.decls.get(name)
        if decl is None:
            raise ParamError(f"unknown parameter {name!r}")
        if (problem := decl.check(float(value))) is not None:
            raise ParamError(problem)
        alias = self.aliases.get(name)
        if alias is None:
            return {name: float(value)}
        updates = alias.plan(float(value), self.values)
        if isinstance(updates, str):
            raise ParamError(f"{name}: {updates}")
        for own, own_value in updates.items():
            if (problem := self.decls[own].check(own_value)) is not None:
                raise ParamError(f"{name} {value:g} would set {problem}")
        return updates

    def write(self, name: str, value: float) -> dict[str, float]:
        """Set and persist; the stored values changed. ParamError: nothing changed."""
        updates = self.plan(name, value)
        self.values.update(updates)
        self.save()
        return updates

    def set(self, name: str, value: float) -> float:
        """Set and persist; the value now read. ParamError (old value kept) as ``plan``."""
        self.write(name, value)
        return self.get(name)

    def reset(self) -> dict[str, float]:
        """Every parameter back to its declared default, persisted at once; the stored
        values that changed (an alias follows its owners)."""
        changed = {
            name: float(self.decls[name].default)
            for name, value in self.values.items()
            if value != self.decls[name].default
        }
        self.values.update(changed)
        self.save()
        return changed

    def linked(self, name: str) -> list[str]:
        """The other names whose value follows ``name``'s: an alias's owners and their
        other aliases, or a parameter's aliases."""
        alias = self.aliases.get(name)
        own = set(alias.sources) if alias is not None else {name}
        related = {a for a, other in self.aliases.items() if own & set(other.sources)}
        if alias is not None:
            related |= own
        return sorted(related - {name})

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
            if name in self.aliases:  # a file from before it was an alias: its owner's holds
                continue
            decl = self.decls.get(name)
            if decl is None and self.partial:
                continue
            if decl is None or not isinstance(value, int | float):
                log.warning("parameter file %s: ignoring %s = %r", path, name, value)
                continue
            if (problem := decl.check(float(value))) is not None:
                log.warning("parameter file %s: ignoring %s", path, problem)
                continue
            self.values[name] = float(value)
