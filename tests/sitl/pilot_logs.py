"""Reading a piloted flight back: the modes from the flight log, the surfaces the servos got."""

from __future__ import annotations

import csv
from pathlib import Path

from pyulog import ULog

from companion.messages import FlightMode


def mode_changes(state_dir: Path) -> list[tuple[float, FlightMode]]:
    """(simulation second, mode) each time vehicle/status showed a new mode, from the
    flight log of the first arming."""
    (log,) = sorted((state_dir / "logs").glob("*_armed.ulg"))[:1]
    data = ULog(str(log)).get_dataset("vehicle_status").data
    out: list[tuple[float, FlightMode]] = []
    for t_us, mode in zip(data["timestamp"], data["mode"], strict=True):
        if not out or out[-1][1] != mode:
            out.append((t_us / 1e6, FlightMode(int(mode))))
    return out


def mission_progress(state_dir: Path) -> list[tuple[float, int, int]]:
    """(simulation second, mission item, items reached) from control/status."""
    (log,) = sorted((state_dir / "logs").glob("*_armed.ulg"))[:1]
    data = ULog(str(log)).get_dataset("control_status").data
    rows = zip(data["timestamp"], data["mission_seq"], data["reached_count"], strict=True)
    return [(t / 1e6, int(seq), int(n)) for t, seq, n in rows]


def first_entry(changes: list[tuple[float, FlightMode]], mode: FlightMode, after: float) -> float:
    """When the vehicle first entered ``mode`` at or after ``after``."""
    for t, m in changes:
        if m == mode and t >= after:
            return t
    raise AssertionError(f"never in {mode.name} after {after} s: {changes}")


def servo_rows(path: Path) -> list[tuple[float, dict[str, float]]]:
    """The servo log: (simulation second, surface → command) per delivery; a servo left out
    of a delivery holds its last position."""
    rows: list[tuple[float, dict[str, float]]] = []
    held: dict[str, float] = {}
    with path.open() as f:
        for r in csv.DictReader(f):
            held = held | {k: float(v) for k, v in r.items() if k != "t" and v}
            rows.append((float(r["t"]), held))
    return rows


def matches(surfaces: dict[str, float], expected: dict[str, float], tol: float = 0.02) -> bool:
    """Whether every expected surface got its command (to the servo card's resolution)."""
    return all(abs(surfaces.get(k, 99.0) - v) <= tol for k, v in expected.items())


def joystick_times(state_dir: Path) -> list[float]:
    """When the link put accepted MANUAL_CONTROL sticks on the bus (simulation seconds)."""
    (log,) = sorted((state_dir / "logs").glob("*_armed.ulg"))[:1]
    return [t / 1e6 for t in ULog(str(log)).get_dataset("link_manual_control").data["timestamp"]]
