"""Plug-ins composed into fewer OS processes, as the config asks (``process = "NAME"``).

A plug-in entry without ``process`` runs in an OS process of its own, as always. Entries
that name the same process share one: the supervisor starts it as one child, and inside it
each plug-in runs on its own thread with the same init/step/close contract, bus channels
and health row (``composed_host``). A process may hold plug-ins of both groups: it runs
while the vehicle does, and starts and stops its ``flight`` plug-ins itself as START and
STOP start and stop the flight group (``flight_members``). These are the config's checks
of such a grouping.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Callable
from typing import Any

from companion.exec_control.config_locator import KeyPath
from companion.exec_control.plugin_spec import PluginSpec

# The config check's error for a key path: an exception carrying the file and line.
ConfigFault = Callable[[KeyPath, str], Exception]

# Linux shows 15 characters of a process name (ps, top); the name is also in bus node names.
PROCESS_NAME = re.compile(r"[a-z][a-z0-9_-]{0,14}")
RESERVED = ("exec_control", "fork_server")


def process_name(error: ConfigFault, entry: dict[str, Any], where: KeyPath) -> str:
    """The entry's ``process`` ("" when it has none), refused when it is no fit name."""
    if "process" not in entry:
        return ""
    name = entry["process"]
    if not isinstance(name, str) or not PROCESS_NAME.fullmatch(name) or name in RESERVED:
        raise error(
            (*where, "process"),
            f"process {name!r} must be 1-15 characters of a-z, 0-9, '_' or '-', starting"
            f" with a letter, and none of {list(RESERVED)}",
        )
    return name


def check_processes(error: ConfigFault, specs: list[PluginSpec]) -> None:
    """Refuse groupings the supervisor could not run as the config means them."""
    members: dict[str, list[int]] = defaultdict(list)
    for index, spec in enumerate(specs):
        if spec.process:
            members[spec.process].append(index)
    names = {spec.name for spec in specs}
    for process, indexes in members.items():
        hosted = {specs[i].name for i in indexes}
        if process in names and process not in hosted:
            raise error(
                ("plugins", indexes[0], "process"),
                f"process {process!r} has the name of a plug-in it does not hold;"
                " `companion status` would be ambiguous",
            )


def process_group(members: list[PluginSpec]) -> str:
    """The group a process of these plug-ins belongs to: ``flight`` only when all of them
    are (START and STOP then start and stop the whole process), else ``core``."""
    return "flight" if all(m.group == "flight" for m in members) else "core"


def flight_members(members: list[dict[str, Any]]) -> list[str]:
    """The plug-ins (their specs) a ``core`` process starts and stops itself with the flight
    group: its ``flight`` ones, when it holds plug-ins of both groups."""
    groups = {m["group"] for m in members}
    return [m["name"] for m in members if m["group"] == "flight"] if len(groups) > 1 else []


def processes(specs: list[PluginSpec]) -> list[tuple[str, list[PluginSpec]]]:
    """The OS processes of a config in order of first appearance: (name, its plug-ins).
    A plug-in of no named process is a process of its own, named ""."""
    out: list[tuple[str, list[PluginSpec]]] = []
    shared: dict[str, list[PluginSpec]] = {}
    for spec in specs:
        if not spec.process:
            out.append(("", [spec]))
        elif spec.process in shared:
            shared[spec.process].append(spec)
        else:
            shared[spec.process] = [spec]
            out.append((spec.process, shared[spec.process]))
    return out


def start_rank(specs: list[PluginSpec]) -> dict[str, int]:
    """0 for the plug-ins a flight in the air waits for, 1 for the rest: the supervisor
    starts them in that order (each in config order), as one at a time they take a tenth of
    a second each on a busy board, and a supervisor restarted in the air has 3 s in all.

    A flight waits for the flight chain (a raised priority: the IMU, the navigator, the
    receiver; the flight group), the commander (it writes ``vehicle/status``: it judges
    whether the restart is in the air and arms again), and whatever writes a required
    input of theirs (the GPS the navigator aligns on in the air, the link's commands).
    """
    first = {s.name for s in specs if s.nice < 0 or s.group == "flight"}
    first |= {s.name for s in specs if "vehicle/status" in s.ports.outputs}
    wanted = {ch for s in specs if s.name in first for ch in s.ports.inputs}
    first |= {s.name for s in specs if wanted.intersection(s.ports.outputs)}
    return {s.name: 0 if s.name in first else 1 for s in specs}
