"""One plug-in instance as a checked config declares it: what the supervisor starts."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from companion.plugin import Ports


@dataclass(frozen=True)
class PluginSpec:
    """One plug-in instance as the config declares it, settings validated."""

    name: str
    kind: str  # the plug-in name as written: short name or module:Class
    group: str
    settings: dict[str, Any]
    ports: Ports
    line: int | None = None
    params: tuple[Any, ...] = ()  # the plug-in class's ParamDecl declarations
    process: str = ""  # the OS process it shares with others ("": a process of its own)
    nice: int = 0  # the Linux nice value it asks for (companion.exec_control.priority)
