"""The commands of the vehicle's MAVLink shell, as text: a command line in, its output out.

What a PX4 user types first in QGroundControl's MAVLink Console (``help``, ``ver``, ``top``,
``param show``) answers with this vehicle's facts: its versions, the plug-ins as
``companion status`` shows them, its parameters. Read-only on purpose: a parameter is set
where its range is checked and its owner told (Vehicle Setup → Parameters, PARAM_SET), and
nothing typed here moves the aircraft.
"""

from __future__ import annotations

import fnmatch
import math
import platform
from collections.abc import Callable
from dataclasses import dataclass

from companion import __version__
from companion.link.px4_compat import PX4_COMPAT_VERSION
from companion.messages import PluginState, SystemHealth
from companion.params.store import ParamStore

MAX_OUTPUT_LINES = 120  # a radio modem carries ~5 kB/s: a longer answer is cut, and says so


@dataclass
class ShellFacts:
    """Where the shell's answers come from."""

    health: Callable[[], SystemHealth | None]  # the execution control's newest table
    params: ParamStore


def run_command(line: str, facts: ShellFacts) -> str:
    """The output of one command line (each line ending in a newline; "" for a blank line)."""
    words = line.split()
    if not words:
        return ""
    name, args = words[0], words[1:]
    command = COMMANDS.get(name)
    if command is None:
        return f"{name}: command not found (help: the commands)\n"
    lines = command[0](args, facts)
    if len(lines) > MAX_OUTPUT_LINES:
        left = len(lines) - MAX_OUTPUT_LINES
        lines = [*lines[:MAX_OUTPUT_LINES], f"... {left} more lines: narrow it (help)"]
    return "".join(f"{text}\n" for text in lines)


def _help(args: list[str], facts: ShellFacts) -> list[str]:
    return [f"  {name:<11} {doc}" for name, (_, doc) in COMMANDS.items()]


def _ver(args: list[str], facts: ShellFacts) -> list[str]:
    px4 = ".".join(map(str, PX4_COMPAT_VERSION))
    return [
        f"companion {__version__} (MAVLink companion computer, a fixed wing)",
        f"follows PX4 {px4} (what QGroundControl shows as the firmware version)",
        f"Python {platform.python_version()}, {platform.system()} {platform.machine()}",
    ]


def _top(args: list[str], facts: ShellFacts) -> list[str]:
    table = facts.health()
    if table is None:
        return ["no health table yet (the supervisor publishes it once a second)"]
    armed = "armed: flight group running" if table.flight_running else "disarmed"
    out = [f"supervisor pid {table.supervisor_pid}, {armed}"]
    out.append(f"{'plug-in':<10} {'state':<8} {'pid':>7} {'restarts':>8} {'CPU %':>6} "
               f"{'frames ok':>10} {'bad':>6} {'dropped':>7}  process")  # fmt: skip
    for row in table.rows():
        name, process = row.name.decode(errors="replace"), row.process.decode(errors="replace")
        state = PluginState(row.state).name.lower() if row.state in _STATES else "?"
        out.append(f"{name:<10} {state:<8} {row.pid or '-':>7} {row.restarts:>8} "
                   f"{row.cpu_pct:>6.1f} {row.frames_ok:>10} {row.frames_bad:>6} "
                   f"{row.dropped:>7}  {process or '(own)'}")  # fmt: skip
    return out


def _param(args: list[str], facts: ShellFacts) -> list[str]:
    if not args or args[0] != "show":
        return ["usage: param show [PATTERN]   (PATTERN as RTL_* or *ALT*; set them in"
                " Vehicle Setup → Parameters)"]  # fmt: skip
    pattern = args[1].upper() if len(args) > 1 else "*"
    store = facts.params
    names = [n for n in store.decls if fnmatch.fnmatchcase(n.upper(), pattern)]
    out = []
    for name in names:
        value, unit = store.get(name), store.decls[name].unit
        shown = f"{value:g}" if math.isfinite(value) else str(value)
        out.append(f"{name}: {shown}{' ' + unit if unit else ''}")
    out.append(f"{len(names)} of {len(store)} parameters")
    return out


_STATES = {int(s) for s in PluginState}
COMMANDS: dict[str, tuple[Callable[[list[str], ShellFacts], list[str]], str]] = {
    "help": (_help, "these commands"),
    "ver": (_ver, "the software's and the platform's versions"),
    "top": (_top, "every plug-in: state, pid, restarts, CPU, counters (companion status)"),
    "param": (_param, "param show [PATTERN]: the parameters and their values"),
}
COMMANDS["status"] = (_top, "the same as top")
