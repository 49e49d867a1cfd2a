"""What the user asked of ``companion sim``, as the command line hands it on.

Plain records, light to import: the command line builds them before it hands its process
over, and imports nothing of the simulation or the vehicle to do so.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from bridges.jsbsim.options import BridgeOptions

if TYPE_CHECKING:
    from companion.control.mission.items import MissionItem

GCS_LINK = "udpout://127.0.0.1:14550"  # QGroundControl, shared by every vehicle


@dataclass
class SimRequest:
    """What the user asked of ``companion sim`` beyond the bridge's options."""

    config: Path
    links: list[str]
    state_dir: str | None = None
    plan: dict[int, list[MissionItem]] | None = None  # checked .plan lists to preload
    sysid: int | None = None  # overrides the config's [vehicle] sysid (one of a fleet)


@dataclass(frozen=True)
class FleetRequest:
    """What the user asked of ``companion sim --count N``."""

    count: int
    opts: BridgeOptions  # the fleet's options; home, namespace, seed, truth are per vehicle
    config: Path
    state_dir: Path
    links: list[str]  # shared endpoints (every vehicle)
    spacing_m: float = 50.0
    api_port_base: int = 14540  # 0: no per-vehicle API port
    plan: Path | None = None
    log_level: str = "INFO"
