"""The standard modes protocol and the heartbeat's view of the mode.

CURRENT_MODE is streamed and sent on every change; AVAILABLE_MODES is sent on request, all
of them (param2 = 0) or one by its 1-based index, as QGroundControl asks; the monitor's
sequence number never changes because the set of modes never does. Until the commander
has spoken, the mode reported is the ``assumed`` one: the commander's initial mode on a
vehicle without a commander, none (no CURRENT_MODE, an unknown custom mode) where a
commander runs, since a link restarted in flight would otherwise announce a false mode.
Every custom_mode is in the reported autopilot's numbering (``px4``: PX4's packing, else
ArduPlane's numbers, ``companion.control.modes``).
"""

from __future__ import annotations

from typing import Any

from companion.control.modes import BY_MODE, INITIAL_MODE, MODES, ModeInfo
from companion.messages import FlightMode, VehicleStatus
from mavlink_dialect import companion as d

MODES_SEQ = 1


def _info(status: VehicleStatus | None, assumed: FlightMode | None) -> ModeInfo | None:
    if status is None:  # the commander has not spoken yet
        return None if assumed is None else BY_MODE[assumed]
    try:
        return BY_MODE[FlightMode(status.mode)]
    except ValueError:
        return None


def heartbeat_mode(
    status: VehicleStatus | None, assumed: FlightMode | None = INITIAL_MODE, px4: bool = True
) -> tuple[int, int]:
    """(custom_mode, extra base_mode flags) for the heartbeat; (0, 0) for no known mode."""
    info = _info(status, assumed)
    return (info.custom_mode(px4), info.base_flags) if info else (0, 0)


def current_mode(
    mav: Any,
    status: VehicleStatus | None,
    assumed: FlightMode | None = INITIAL_MODE,
    px4: bool = True,
) -> Any:
    """CURRENT_MODE (the ``assumed`` mode before the commander has spoken; None for none)."""
    info = _info(status, assumed)
    if info is None:
        return None
    custom = info.custom_mode(px4)
    return mav.current_mode_encode(info.standard, custom, custom)


def available_modes(mav: Any, index: int, px4: bool = True) -> list[Any]:
    """AVAILABLE_MODES: every mode for index 0, else the one at that 1-based index."""
    chosen = range(1, len(MODES) + 1) if index == 0 else [index]
    out = []
    for i in chosen:
        if not 1 <= i <= len(MODES):
            continue
        info = MODES[i - 1]
        props = 0 if info.user_selectable else d.MAV_MODE_PROPERTY_NOT_USER_SELECTABLE
        out.append(
            mav.available_modes_encode(
                len(MODES), i, info.standard, info.custom_mode(px4), props, info.name.encode()
            )
        )
    return out


def available_modes_monitor(mav: Any) -> Any:
    """AVAILABLE_MODES_MONITOR with the (constant) sequence of the mode set."""
    return mav.available_modes_monitor_encode(MODES_SEQ)
