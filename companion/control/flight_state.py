"""What a restarted commander needs to carry a flight on: armed, mode, home, target, item
and the airspeed a DO_CHANGE_SPEED asked for.

The commander writes it (atomically) each time it changes, and reads it back when its
process starts again. It is used only when the sensors agree that the flight is still on
(``in_the_air``) or the execution control still holds the aircraft armed: a file left by
an earlier flight never arms an aircraft standing on the ground. As ArduPilot restores its
armed state and mode after an in-flight watchdog reset, the aircraft then keeps flying
its mode, and a mission goes on from the item it was flying to.
"""

from __future__ import annotations

import json
import logging
import math
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from companion.control.flight.on_ground import LANDED_SPEED
from companion.messages import FlightMode
from companion.messages.navigation import NAV_POSITION_VALID
from companion.params.atomic import atomic_write_text

log = logging.getLogger(__name__)

FILE_NAME = "flight_state.json"
# In the air, judged by the navigator: faster than the controller's on-the-ground speed, or
# well above home (higher than its 10 m: a resumed flight is armed without pre-arm checks).
AIRBORNE_HEIGHT_M = 15.0


@dataclass(frozen=True)
class FlightState:
    """The commander's part of a flight, as it was last written."""

    armed: bool
    mode: int  # FlightMode
    home: tuple[float, float, float] | None
    target: tuple[float, float, float]  # GUIDED / LOITER point (NaN when none)
    radius: float  # NaN: the default circle
    mission_seq: int  # the item the mission was flying to
    changes: int  # accepted mode commands (the controller's "new mode" key)
    go_arounds: int
    mission_jumps: int = 0  # set-currents accepted (an older file has none: 0)
    mission_jump_to: int = -1  # the item of the last (-1: none)
    speed: float = math.nan  # DO_CHANGE_SPEED's airspeed, m/s (NaN: the cruise; older files)

    def to_json(self) -> str:
        """One JSON object; NaN written as null."""
        data = asdict(self)
        data["target"] = [_finite_or_none(v) for v in self.target]
        data["radius"] = _finite_or_none(self.radius)
        data["speed"] = _finite_or_none(self.speed)
        return json.dumps(data)

    @classmethod
    def from_json(cls, text: str) -> FlightState:
        """The state a file holds; ValueError for anything that is not one."""
        try:
            data: dict[str, Any] = json.loads(text)
            mode = int(FlightMode(int(data["mode"])))
            home = data["home"]
            state = cls(
                armed=bool(data["armed"]),
                mode=mode,
                home=None if home is None else _place(home),
                target=tuple(_nan_if_none(v) for v in data["target"]),  # type: ignore[arg-type]
                radius=_nan_if_none(data["radius"]),
                mission_seq=max(0, int(data["mission_seq"])),
                changes=max(0, int(data["changes"])),
                go_arounds=max(0, int(data["go_arounds"])),
                mission_jumps=max(0, int(data.get("mission_jumps", 0))),
                mission_jump_to=max(-1, int(data.get("mission_jump_to", -1))),
                speed=_nan_if_none(data.get("speed")),
            )
        except (KeyError, TypeError, ValueError, OverflowError) as exc:
            raise ValueError(f"not a flight state: {exc}") from None
        if not (math.isnan(state.speed) or state.speed > 0):
            raise ValueError(f"not a flight state: airspeed {state.speed:g}")
        if len(state.target) != 3:
            raise ValueError("not a flight state: target is not a point")
        return state


def save_flight_state(state_dir: Path, state: FlightState) -> None:
    """Write it so that a power cut leaves the old state or the new, never half."""
    atomic_write_text(state_dir / FILE_NAME, state.to_json())


def load_flight_state(state_dir: Path) -> FlightState | None:
    """The last state written, or None (none written, or a file that is not one)."""
    path = state_dir / FILE_NAME
    try:
        return FlightState.from_json(path.read_text())
    except FileNotFoundError:
        return None
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        log.warning("%s ignored: %s", path, exc)
        return None


def in_the_air(nav: Any, home: tuple[float, float, float] | None) -> bool:
    """Whether the navigator says the aircraft flies: fast, or high above home."""
    if nav is None or not nav.flags & NAV_POSITION_VALID:
        return False
    if math.hypot(nav.vn_m_s, nav.ve_m_s) >= LANDED_SPEED:
        return True
    return home is not None and nav.alt_msl_m - home[2] >= AIRBORNE_HEIGHT_M


def _finite_or_none(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _nan_if_none(value: Any) -> float:
    if value is None:
        return math.nan
    number = float(value)
    if not math.isfinite(number):
        raise ValueError("a number that is not finite")
    return number


def _place(value: Any) -> tuple[float, float, float]:
    lat, lon, alt = (float(v) for v in value)
    if not (-90.0 <= lat <= 90.0 and -180.0 <= lon <= 180.0 and math.isfinite(alt)):
        raise ValueError("home is not a place")
    return lat, lon, alt
