"""A parameter under another autopilot's name: a view of the vehicle's own, never a copy.

QGroundControl's PX4 pages read and write PX4's names (NAV_RCL_ACT, RTL_RETURN_ALT, ...);
the vehicle flies by its own (THR_FAILSAFE, RTL_ALT_M, ...). An ``Alias`` says how one is
read as the other, so there is one value: reading the alias converts its owners' values
as they are now, writing it converts the value and sets theirs (the owners follow
``params/changes`` as for any change), and a value they cannot express is refused.

The forms, all plain data (declarations travel to every plug-in as JSON):
- linear: alias = own * scale (one target), or own / values[divisor] * scale, a fraction
  of another parameter (a charge threshold of the pack's capacity); ``times`` multiplies by
  another parameter, ``inverse`` takes 1 / own (a time constant from a gain: another
  autopilot's FW_R_TC is the vehicle's RLL_D / RLL_P); a divisor or factor at 0 reads 0;
- table: rows of (alias value, the targets' values in order). Reading takes the first row
  the targets match, rounded as their owners read them (0.5 and above is on), else
  ``other``; writing takes the first row with that alias value, and an alias value with
  no row (``other`` included) cannot be honoured. A table without rows reads ``other``
  whenever its targets are declared: a fact about which plug-ins the vehicle runs;
- ``writable`` false: any write but the value it already reads is refused.
Pure: no store, no bus (``companion.params.store`` binds aliases to their owners).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

Row = tuple[float, tuple[float, ...]]


def _same(a: float, b: float) -> bool:
    """Equal as a float32 on the wire makes them."""
    return math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-9)


def _as_read(value: float) -> float:
    """An owner's switch or enumeration as its owner reads it (0.5 and above is 1)."""
    return float(math.floor(value + 0.5))


@dataclass(frozen=True)
class Alias:
    """How a parameter reads and writes the vehicle's own (``targets``)."""

    targets: tuple[str, ...]
    scale: float = 1.0
    divisor: str = ""  # linear: a fraction of this parameter
    times: str = ""  # linear: times this parameter
    inverse: bool = False  # linear: of 1 / own
    table: tuple[Row, ...] | None = None
    other: float = 0.0  # table: what no row matches reads as
    writable: bool = True

    def __post_init__(self) -> None:  # lists, as JSON brings them back, become tuples
        object.__setattr__(self, "targets", tuple(self.targets))
        if self.table is not None:
            rows = tuple((float(a), tuple(float(v) for v in owns)) for a, owns in self.table)
            if any(len(owns) != len(self.targets) for _, owns in rows):
                raise ValueError(f"alias of {self.targets}: a row per target value")
            object.__setattr__(self, "table", rows)
        elif len(self.targets) != 1 or self.scale == 0:
            raise ValueError(f"linear alias of {self.targets}: one target, a scale")

    @property
    def sources(self) -> tuple[str, ...]:
        """Every parameter the alias reads."""
        return (*self.targets, *(name for name in (self.divisor, self.times) if name))

    @property
    def linear_only(self) -> bool:
        """Plain own * scale: the owner's range, scaled, is the alias's."""
        return self.table is None and not (self.divisor or self.times or self.inverse)

    def read(self, values: Mapping[str, float]) -> float:
        """The alias's value given the owners' values."""
        if self.table is None:
            own = values[self.targets[0]]
            if self.inverse:
                own = 1.0 / own if own != 0 else 0.0
            factor = values[self.times] if self.times else 1.0
            whole = values[self.divisor] if self.divisor else 1.0
            return own * self.scale * factor / whole if whole > 0 else 0.0
        for value, owns in self.table:
            if all(_as_read(values[t]) == o for t, o in zip(self.targets, owns, strict=True)):
                return value
        return self.other

    def plan(self, value: float, values: Mapping[str, float]) -> dict[str, float] | str:
        """The targets' new values for ``value`` (none if it already reads so), or why
        the owners cannot honour it."""
        if _same(self.read(values), value):
            return {}
        if not self.writable:
            return f"{value:g} cannot be set here (it follows {', '.join(self.sources)})"
        if self.table is not None:
            for row_value, owns in self.table:
                if _same(row_value, value):
                    return dict(zip(self.targets, owns, strict=True))
            return f"{value:g} is not something this vehicle can do"
        own = value / self.scale
        for name in (self.divisor, self.times):
            if name and values[name] <= 0:
                return f"{value:g} needs {name} above 0"
        own = own * (values[self.divisor] if self.divisor else 1.0)
        own = own / (values[self.times] if self.times else 1.0)
        if self.inverse:
            if own == 0:
                return f"{value:g} cannot be 0 (it is 1 / {self.targets[0]})"
            own = 1.0 / own
        return {self.targets[0]: own}
