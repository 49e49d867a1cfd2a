"""A plug-in's own parameters, kept current while it runs.

The link owns the parameter store and writes it; an owner reads the stored values once
at start and then follows ``params/changes``, so a value set from the ground station
takes effect at once without a restart.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from companion.params.store import ParamDecl, ParamStore


class LiveParams:
    """Name → value for the declared parameters; ``poll()`` applies changes."""

    def __init__(self, bus: Any, decls: Iterable[ParamDecl], state_dir: Path) -> None:
        decls = tuple(decls)
        stored = ParamStore(decls, state_dir / "params.json", partial=True)
        self.values = {d.name: stored.get(d.name) for d in decls}
        self._decls = {d.name: d for d in decls}
        self._changes = bus.queue_reader("params/changes")

    def __getitem__(self, name: str) -> float:
        return self.values[name]

    def poll(self) -> bool:
        """Apply the changes published since the last call; True when any applied."""
        changed = False
        for change in self._changes.drain():
            name = change.name.decode(errors="replace")
            decl = self._decls.get(name)
            if decl is not None and decl.check(change.value) is None:  # finite, in range
                self.values[name] = change.value
                changed = True
        return changed
