"""Parameter files: QGroundControl's ``.params`` (``vehicle-id component-id name value
type`` per line, what ``save_params`` writes), and read also as ArduPilot users have them:
MAVProxy's ``param save`` (``NAME VALUE``) and Mission Planner's ``.param`` (``NAME,VALUE``).

A file lists every parameter the vehicle serves, so it lists an alias (a PX4 name such as
RTL_RETURN_ALT, which follows RTL_ALT_M) beside the parameters it follows: ``save_params``
writes them all, as QGroundControl's "Save to file" and MAVProxy's ``param save`` write
every value the vehicle sent. Reading one back, the file's own values come first and each
alias line is then read against them, not against the vehicle's values of the moment: a
line that agrees with what it follows sets nothing more, one that contradicts it is
refused, naming both.
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass
from pathlib import Path

from companion.params.atomic import atomic_write_text
from companion.params.store import ParamError, ParamStore, same_value

MAV_PARAM_TYPE_REAL32 = 9

log = logging.getLogger(__name__)


def save_params(store: ParamStore, path: Path, sysid: int = 1, compid: int = 1) -> None:
    """Write every parameter in QGroundControl's tab-separated format."""
    lines = ["# Onboard parameters for companion", "#", "# Vehicle-Id Component-Id Name Value Type"]
    for name in store.names:
        lines.append(f"{sysid}\t{compid}\t{name}\t{store.get(name)!r}\t{MAV_PARAM_TYPE_REAL32}")
    atomic_write_text(path, "\n".join(lines) + "\n", shared=True)


@dataclass(frozen=True)
class _Line:
    lineno: int
    name: str
    value: float
    printed_tol: float = 0.0  # half the last printed digit: MAVProxy writes 6 decimals


MAVPROXY_DECIMALS = 6  # its `param save` prints "%f"


def _printed_tol(text: str) -> float:
    """How far a value MAVProxy wrote as ``text`` may be from the one it printed."""
    _, dot, decimals = text.partition(".")
    return 0.5 * 10.0**-MAVPROXY_DECIMALS if dot and len(decimals) == MAVPROXY_DECIMALS else 0.0


FORMATS = (
    "'sysid compid NAME VALUE type' (QGroundControl), 'NAME VALUE' (MAVProxy)"
    " or 'NAME,VALUE' (Mission Planner)"
)


def _name_and_value(line: str) -> tuple[str, str, float] | None:
    """A line's name, value and how far the value may be from what was printed (MAVProxy's
    six decimals), in any of the three formats (None: in none of them)."""
    comma = "," in line
    fields = [f.strip() for f in line.split(",")] if comma else line.split()
    if len(fields) == 2:
        return fields[0], fields[1], 0.0 if comma else _printed_tol(fields[1])
    if len(fields) >= 4 and not comma:  # QGroundControl's: full precision
        return fields[2], fields[3], 0.0
    return None


def _lines(path: Path) -> list[_Line]:
    """The file's parameter lines; ParamError names the first that is not one."""
    lines = []
    for lineno, raw in enumerate(path.read_text().splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        found = _name_and_value(line)
        if found is None:
            raise ParamError(f"{path}:{lineno}: expected {FORMATS}")
        name, text, tol = found
        try:
            lines.append(_Line(lineno, name, float(text), tol))
        except ValueError:
            raise ParamError(f"{path}:{lineno}: {name}: {text!r} is not a number") from None
    return lines


class _FilePlan:
    """The stored values a file sets, each with the line that set it."""

    def __init__(self, store: ParamStore, path: Path) -> None:
        self.store, self.path = store, path
        self.values = dict(store.values)  # the vehicle's, then the file's over them
        self.set_by: dict[str, _Line] = {}
        self.unknown: list[str] = []  # names this config does not declare: skipped

    def error(self, line: _Line, text: str) -> ParamError:
        return ParamError(f"{self.path}:{line.lineno}: {text}")

    def own(self, line: _Line) -> None:
        """A parameter of the vehicle's own: its value, checked. One printed within its
        last digit of the vehicle's value is that value, not a rounding of it."""
        decl = self.store.decls.get(line.name)
        if decl is None:
            # A file from a vehicle with more plug-ins (or another version) is loaded as
            # QGroundControl and MAVProxy load one: the rest of it, the name reported.
            log.warning("%s:%d: %s not set: no such parameter here",
                        self.path, line.lineno, line.name)  # fmt: skip
            self.unknown.append(line.name)
            return
        if decl.min == decl.max and not same_value(decl.min, line.value):
            # A fact of the vehicle the file came from (its system id, a battery monitor
            # it had): not a setting, and this vehicle's stays.
            log.warning("%s:%d: %s %g not set: this vehicle's is %g (fixed)",
                        self.path, line.lineno, line.name, line.value, decl.min)  # fmt: skip
            return
        current = self.values.get(line.name)
        if current is not None and abs(current - line.value) <= line.printed_tol:
            line = dataclasses.replace(line, value=current)
        try:
            self.store.plan(line.name, line.value)
        except ParamError as exc:
            raise self.error(line, str(exc)) from None
        earlier = self.set_by.get(line.name)
        if earlier is not None and not same_value(earlier.value, line.value):
            raise self.error(line, f"{line.name} disagrees with line {earlier.lineno}")
        self.values[line.name] = line.value
        self.set_by[line.name] = line

    def alias(self, line: _Line) -> bool:
        """An alias, read against the file's values: nothing to do when it agrees (what it
        follows was checked), its owners' values when it sets them; whether it changed any.
        One that cannot be written is checked once the others have set what it reads."""
        if self.agrees(line) or not self.store.aliases[line.name].writable:
            return False
        try:
            planned = self.store.plan(line.name, line.value, self.values)
        except ParamError as exc:
            raise self.error(line, str(exc)) from None
        for own, value in planned.items():
            earlier = self.set_by.get(own, line)
            if earlier is not line and not same_value(self.values[own], value):
                raise self.contradiction(line, (own,))
        self.values.update(planned)
        self.set_by.update(dict.fromkeys(planned, line))
        return bool(planned)

    def agrees(self, line: _Line) -> bool:
        """The alias of ``line`` reads its value from the file's values, to the digits the
        file printed (MAVProxy's 0.133333 is 1/7.5): the alias's own last digit and what
        the last digits of the values it reads move it by."""
        alias = self.store.aliases[line.name]
        read = alias.read(self.values)
        if same_value(read, line.value):
            return True
        slack = line.printed_tol
        for source in alias.sources:
            setter = self.set_by.get(source)
            if setter is not None and setter.printed_tol:
                bumped = {**self.values, source: self.values[source] + setter.printed_tol}
                slack += abs(alias.read(bumped) - read)
        return abs(read - line.value) <= slack * (1 + 1e-6) + 1e-12

    def contradiction(self, line: _Line, owners: tuple[str, ...]) -> ParamError:
        """``line``'s alias reads otherwise than the values it follows."""
        sources = ", ".join(self.store.aliases[line.name].sources)
        others = [o for o in owners if self.set_by.get(o, line) is not line]
        owner = (others or [o for o in owners if o not in self.set_by] or list(owners))[0]
        leader = self.set_by.get(owner)
        if leader is None:
            said = f"{owner} {self.values[owner]:g} (the vehicle's; not in the file)"
        elif leader is line:
            said = f"{owner} {self.values[owner]:g}"
        else:
            said = f"{leader.name} {leader.value:g} (line {leader.lineno})"
        text = f"{line.name} {line.value:g} contradicts {said}: {line.name} follows {sources}"
        return self.error(line, text)


def load_params(store: ParamStore, path: Path) -> int:
    """Apply a parameter file (any of the three formats); how many of its lines name a
    parameter of this config. ParamError names the line and parameter of the first bad line.

    Nothing is applied unless every line is good; a name the config does not declare is
    skipped, with a warning. A line at the parameter's default stores
    nothing (the parameter keeps following its default), so a whole file written by
    ``save_params`` stores only the values that differ. An alias's line that agrees with the
    file's values of the parameters it follows sets nothing; one that does not sets them
    (when the alias can be written and the file does not give them otherwise); a line that
    contradicts another is an error naming both.
    """
    lines = _lines(path)
    plan = _FilePlan(store, path)
    for line in lines:
        if line.name not in store.aliases:
            plan.own(line)
    followers = [line for line in lines if line.name in store.aliases]
    for _ in range(len(followers) + 1):  # one alias may read what another sets
        changed = [plan.alias(line) for line in followers]
        if not any(changed):
            break
    for line in followers:
        if not plan.agrees(line):
            raise plan.contradiction(line, store.aliases[line.name].sources)
    store.apply({own: plan.values[own] for own in plan.set_by})
    return len(lines) - len(plan.unknown)
