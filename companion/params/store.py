"""The parameter store: declarations merged from their owners, values checked and kept.

Every value is a float on the wire (MAV_PARAM_TYPE_REAL32, the one encoding QGroundControl,
MAVSDK and MAVProxy agree on). A set outside a parameter's range, or not one of its
enumerated values, is refused and the old value kept. An alias (``companion.params.alias``)
has no value of its own: it is read from, and written to, the parameters it stands for.

Only what the user set is stored (``params.json``: ``{"format": 2, "set": {...}}``), as
ArduPilot and PX4 do; every other parameter follows its declared default or the airframe
file's value, now and after either changes. Setting a parameter to its default takes it
out of the stored set again (QGroundControl's "reset to default" sends the default), and a
reset to defaults empties it. The file is written atomically and read at start; a stored
value that no longer fits its declaration, or a corrupt file, is logged and ignored. A
stored value of a parameter this config does not declare (its plug-in left out for now)
is kept in the file, untouched.

A file from before (a flat table of every parameter, each pinned) is read by one rule: a
value equal to the parameter's current default (declared or airframe) is dropped, as one
the user never changed; any other is kept as set. ``legacy`` then says what was done, and
the owner of the file (the link) writes it back in the new form at once, so the rule
meets each old file only once, against the defaults it was written with.
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
FORMAT = 2  # params.json holds only the values the user set


def same_value(a: float, b: float) -> bool:
    """Equal as a float32 on the wire leaves them (a default sent back by a ground station)."""
    return math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-9)


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
    origin: str = "default"  # where ``default`` comes from: "default" or "airframe NAME"
    integer: bool = False  # whole numbers only (a channel's number): 2.5 is refused

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

    @classmethod
    def switch(
        cls, name: str, default: float, doc: str, off: str = "Disabled", on: str = "Enabled"
    ) -> ParamDecl:
        """A parameter that is 0 or 1 and nothing between (a half-enabled failsafe would
        read as on in one place and off in another), offered as two named choices."""
        return cls(name, default, 0.0, 1.0, "", doc, values=((0.0, off), (1.0, on)))

    def check(self, value: float) -> str | None:
        """Why ``value`` is not acceptable, or None."""
        if not math.isfinite(value):
            return f"{self.name}: {value} is not a finite number"
        if value < self.min or value > self.max:
            return f"{self.name}: {value:g} outside [{self.min:g}, {self.max:g}]"
        if self.integer and value != math.floor(value):
            return f"{self.name}: {value:g} is not a whole number"
        if self.values and not any(math.isclose(value, v, abs_tol=1e-6) for v, _ in self.values):
            allowed = ", ".join(f"{v:g}" for v, _ in self.values)
            return f"{self.name}: {value:g} is not one of {allowed}"
        return None


def declared_values(decls: Iterable[ParamDecl], values: Mapping[str, float]) -> dict[str, float]:
    """Each declared parameter's value in ``values`` (name → value), its default where it
    has none: what a part's config reads its own parameters from."""
    return {p.name: float(values.get(p.name, p.default)) for p in decls}


def bind(decl: ParamDecl, decls: Mapping[str, ParamDecl]) -> ParamDecl:
    """An alias as this vehicle serves it: its default (and a linear one's range) from its
    owners' declarations; a fixed fact at its own default when an owner is not there."""
    alias = decl.alias
    assert alias is not None
    missing = [s for s in alias.sources if s not in decls or decls[s].alias is not None]
    if missing:
        doc = f"{decl.doc} [fixed: no {', '.join(missing)} on this vehicle]"
        values = tuple(v for v in decl.values if v[0] == decl.default)
        fixed = decl.default
        return replace(decl, alias=None, doc=doc, min=fixed, max=fixed, values=values)
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
        self.stored: dict[str, float] = {}  # what the user set; ``values`` holds them too
        self.foreign: dict[str, Any] = {}  # stored for parameters this config does not declare
        self.legacy: tuple[list[str], list[str]] | None = None  # an old file: kept, dropped
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

    def plan(
        self, name: str, value: float, values: Mapping[str, float] | None = None
    ) -> dict[str, float]:
        """The stored values a set would change (an alias's: its owners'); ParamError when
        unknown, out of range or not something the owners can honour. ``values``: the
        stored values to plan against (a file's, before any is applied), else the store's."""
        decl = self.decls.get(name)
        if decl is None:
            raise ParamError(f"unknown parameter {name!r}")
        if (problem := decl.check(float(value))) is not None:
            raise ParamError(problem)
        alias = self.aliases.get(name)
        if alias is None:
            return {name: float(value)}
        updates = alias.plan(float(value), self.values if values is None else values)
        if isinstance(updates, str):
            raise ParamError(f"{name}: {updates}")
        for own, own_value in updates.items():
            if (problem := self.decls[own].check(own_value)) is not None:
                raise ParamError(f"{name} {value:g} would set {problem}")
        return updates

    def write(self, name: str, value: float) -> dict[str, float]:
        """Set and persist; the stored values changed. ParamError: nothing changed."""
        updates = self.plan(name, value)
        self.apply(updates)
        return updates

    def apply(self, updates: Mapping[str, float]) -> None:
        """Store checked values (``plan``'s) as set by the user, and persist them. A value
        equal to its default is not stored: the parameter follows its default again."""
        for name, value in updates.items():
            default = float(self.decls[name].default)
            if same_value(value, default):
                self.values[name] = default
                self.stored.pop(name, None)
            else:
                self.values[name] = self.stored[name] = float(value)
        self.save()

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
        self.stored.clear()
        self.save()
        return changed

    def migrate(self) -> None:
        """An old file (every value pinned) rewritten as the stored set, once, by its owner."""
        if self.legacy is None or self.path is None:
            return
        kept, dropped = self.legacy
        kept_names = ", ".join(kept) or "none"
        log.info(
            "parameter file %s from an older version: %d values at their default dropped, "
            "kept as set: %s", self.path, len(dropped), kept_names,
        )  # fmt: skip
        self.save()
        self.legacy = None

    def source(self, name: str) -> str:
        """Where a value comes from: "stored" (set by the user), the declaration's origin
        ("default", "airframe NAME"), or "alias of NAME..." (read from those parameters)."""
        alias = self.aliases.get(name)
        if alias is not None:
            return f"alias of {', '.join(alias.sources)}"
        return "stored" if name in self.stored else self.decls[name].origin

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
        """Write the stored set (only what the user set) atomically."""
        if self.path is None:
            return
        if self.partial:  # it knows one owner's names: writing would drop the others'
            raise ParamError("a partial parameter store is read-only")
        table = {"format": FORMAT, "set": {**self.foreign, **self.stored}}
        atomic_write_text(self.path, json.dumps(table, indent=1, sort_keys=True))

    def _restore(self, path: Path) -> None:
        table = self._read(path)
        if table is None:
            return
        kept: list[str] = []
        dropped: list[str] = []
        for name, value in table.items():
            if name in self.aliases:  # a file from before it was an alias: its owner's holds
                continue
            decl = self.decls.get(name)
            if decl is None:
                if not self.partial:
                    log.warning("parameter file %s: %s is not declared here (kept)", path, name)
                    self.foreign[name] = value
                continue
            if not isinstance(value, int | float) or isinstance(value, bool):
                log.warning("parameter file %s: ignoring %s = %r", path, name, value)
                continue
            if (problem := decl.check(float(value))) is not None:
                log.warning("parameter file %s: ignoring %s", path, problem)
                continue
            if self.legacy is not None and same_value(float(value), float(decl.default)):
                dropped.append(name)  # an old file pinned every value: this one is a default
                continue
            kept.append(name)
            self.values[name] = self.stored[name] = float(value)
        if self.legacy is not None:
            self.legacy = (kept, dropped)

    def _read(self, path: Path) -> dict[str, Any] | None:
        """The file's table of stored values (``legacy`` set for an old file), or None."""
        try:
            stored = json.loads(path.read_text())
        except FileNotFoundError:
            return None
        except (OSError, ValueError) as exc:
            log.warning("parameter file %s unreadable (%s): using defaults", path, exc)
            return None
        if not isinstance(stored, dict):
            log.warning("parameter file %s is not a table: using defaults", path)
            return None
        if "format" not in stored:
            self.legacy = ([], [])
            return stored
        table = stored.get("set")
        if stored.get("format") != FORMAT or not isinstance(table, dict):
            log.warning("parameter file %s: unknown format: using defaults", path)
            return None
        return table
