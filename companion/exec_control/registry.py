"""Find a plug-in class by the name a config gives it.

Two forms: a registered short name such as ``sensors.nmea_gps`` (entry-point group
``companion.plugins``, so third-party packages can add their own) or an explicit
``"package.module:ClassName"``. The import happens lazily, when asked for.
"""

from __future__ import annotations

import functools
import importlib
import importlib.metadata
from collections.abc import Mapping
from difflib import get_close_matches
from types import MappingProxyType

from companion.plugin import Plugin

ENTRY_POINT_GROUP = "companion.plugins"


class PluginLoadError(Exception):
    """The named plug-in cannot be found or imported."""


@functools.cache
def registered() -> Mapping[str, str]:
    """Short name → ``module:Class`` of every registered plug-in.

    Read once per process: the installed packages do not change under a running vehicle,
    and the supervisor's table is inherited by the fork server and every plug-in it forks.
    Reading the entry points again in each plug-in cost it 1.7 MB of private memory (the
    metadata machinery writes all over pages it shares with the fork server).
    """
    eps = importlib.metadata.entry_points(group=ENTRY_POINT_GROUP)
    return MappingProxyType({ep.name: ep.value for ep in eps})


def target_of(name: str) -> str:
    """The ``module:Class`` a config name stands for; PluginLoadError when unknown."""
    if ":" in name:
        return name
    table = registered()
    if name in table:
        return table[name]
    hint = get_close_matches(name, list(table), n=1)
    did_you_mean = f"; did you mean {hint[0]!r}?" if hint else ""
    known = ", ".join(sorted(table)) or "none"
    raise PluginLoadError(f"unknown plug-in {name!r}{did_you_mean} (registered: {known})")


def load(name: str) -> type[Plugin]:
    """Import and return the plug-in class for a config name."""
    target = target_of(name)
    module_name, _, class_name = target.partition(":")
    if not module_name or not class_name:
        raise PluginLoadError(f"plug-in {name!r}: expected 'package.module:ClassName'")
    try:
        module = importlib.import_module(module_name)
    except Exception as exc:
        raise PluginLoadError(f"plug-in {name!r}: cannot import {module_name}: {exc}") from exc
    cls = getattr(module, class_name, None)
    if cls is None:
        raise PluginLoadError(f"plug-in {name!r}: module {module_name} has no {class_name}")
    if not (isinstance(cls, type) and issubclass(cls, Plugin)):
        raise PluginLoadError(f"plug-in {name!r}: {target} is not a companion Plugin")
    return cls
