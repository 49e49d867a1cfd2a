"""QGroundControl ``.params`` files: ``vehicle-id component-id name value type`` per line."""

from __future__ import annotations

from pathlib import Path

from companion.params.store import ParamError, ParamStore

MAV_PARAM_TYPE_REAL32 = 9


def save_params(store: ParamStore, path: Path, sysid: int = 1, compid: int = 1) -> None:
    """Write every parameter in QGroundControl's tab-separated format."""
    lines = ["# Onboard parameters for companion", "#", "# Vehicle-Id Component-Id Name Value Type"]
    for name in store.names:
        lines.append(f"{sysid}\t{compid}\t{name}\t{store.get(name)!r}\t{MAV_PARAM_TYPE_REAL32}")
    path.write_text("\n".join(lines) + "\n")


def load_params(store: ParamStore, path: Path) -> int:
    """Apply a .params file; ParamError names the line and parameter of the first bad line.

    Nothing is applied unless every line is good. A line at the parameter's default stores
    nothing (the parameter keeps following its default), so a whole file written by
    ``save_params`` stores only the values that differ. An alias's line sets the parameters it
    stands for; two lines that would set one parameter to different values are an error.
    """
    updates: dict[str, tuple[float, str]] = {}  # stored name -> value, the line's name
    count = 0
    for lineno, raw in enumerate(path.read_text().splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        fields = line.split()
        if len(fields) < 4:
            raise ParamError(f"{path}:{lineno}: expected 'sysid compid name value type'")
        name, text = fields[2], fields[3]
        try:
            value = float(text)
        except ValueError:
            raise ParamError(f"{path}:{lineno}: {name}: {text!r} is not a number") from None
        try:
            planned = store.plan(name, value)
        except ParamError as exc:
            raise ParamError(f"{path}:{lineno}: {exc}") from None
        for own, own_value in planned.items():
            earlier = updates.get(own)
            if earlier is not None and earlier[0] != own_value:
                raise ParamError(f"{path}:{lineno}: {name} disagrees with {earlier[1]}")
            updates[own] = (own_value, name)
        count += 1
    store.apply({own: own_value for own, (own_value, _) in updates.items()})
    return count
