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

# The name of a change that replaced every value at once (a reset to defaults): too many
# for the queue, so its readers take the values from the stored file again.
RELOAD_ALL = "*"


class LiveParams:
    """Name → value for the declared parameters; ``poll()`` applies changes."""

    def __init__(self, bus: Any, decls: Iterable[ParamDecl], state_dir: Path) -> None:
        decls = tuple(decls)
        self._path = state_dir / "params.json"
        self._decls = {d.name: d for d in decls}
        self.values = self._stored()
        self._changes = bus.queue_reader("params/changes")

    def _stored(self) -> dict[str, float]:
        stored = ParamStore(self._decls.values(), self._path, partial=True)
        return {name: stored.get(name) for name in self._decls}

    def __getitem__(self, name: str) -> float:
        return self.values[name]

    def poll(self) -> bool:
        """Apply the changes published since the last call; True when any applied."""
        changed = False
        for change in self._changes.pending():  # a list: no generator at every poll
            name = change.name.decode(errors="replace")
            if name == RELOAD_ALL:
                self.values = self._stored()
                changed = True
                continue
            decl = self._decls.get(name)
            if decl is not None and decl.check(change.value) is None:  # finite, in range
                self.values[name] = change.value
                changed = True
        return changed
