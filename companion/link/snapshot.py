"""The newest bus values the link builds its messages from, one field per channel.

Each field names its bus channel (``SNAPSHOT_CHANNELS``, checked against the registry by a
test), so the link subscribes to exactly what its streams read.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

from companion.control.mission.fence import Fence
from companion.control.modes import INITIAL_MODE
from companion.messages import (
    Baro,
    Battery,
    Compass,
    ControlStatus,
    FlightMode,
    GpsFix,
    Imu,
    Magnetometer,
    NavState,
    PilotInput,
    RangeReading,
    ServoOutput,
    SystemHealth,
    VehicleStatus,
)
from companion.messages.channels import CHANNELS


def _newest(channel: str) -> Any:
    """A snapshot field holding the newest value of a bus channel (None before the first);
    its type is the channel's payload type (CHANNELS), as a test checks."""
    return field(default=None, metadata={"channel": channel})


@dataclass
class Snapshot:
    """The newest bus values the streams are built from (the link reads each field's
    channel), and the link's own state they need."""

    time_boot_ms: int = 0
    unix_us: int = 0
    now_us: int = 0  # the vehicle clock when the snapshot was taken (sensor freshness)
    nav: NavState | None = _newest("nav/state")
    gps: GpsFix | None = _newest("sensors/gps")
    imu: Imu | None = _newest("sensors/imu")
    mag: Magnetometer | None = _newest("sensors/mag")
    compass: Compass | None = _newest("sensors/compass")
    baro: Baro | None = _newest("sensors/baro")
    battery: Battery | None = _newest("sensors/battery")
    health: SystemHealth | None = _newest("system/health")
    servos: ServoOutput | None = _newest("actuators/servos")
    rc: PilotInput | None = _newest("sensors/rc")  # the RC receiver's newest frame
    rangefinder: RangeReading | None = _newest("sensors/range")  # the downward lidar's
    status: VehicleStatus | None = _newest("vehicle/status")
    # None while the flight controller is not running (the link judges its freshness).
    control: ControlStatus | None = _newest("control/status")
    home_alt_m: float = math.nan
    mission_seq: int = 0
    mission_total: int = 0
    mission_completed: bool = False  # flown to its end since it was stored
    mission_paused: bool = False  # flown since it was stored, left before its end
    home: tuple[float, float, float] | None = None  # lat_deg, lon_deg, alt_msl_m
    health_cursor: int = 0  # PLUGIN_HEALTH sends one row at a time, round the table
    prearm_ok: bool | None = None  # the pre-arm checks pass (None: not judged yet)
    fence: Fence | None = None  # the stored geofence (None: none stored)
    fence_enabled: bool = False  # FENCE_ENABLE: a breach turns the aircraft home
    # The mode shown before the commander has spoken (None: none, where a commander runs).
    assumed_mode: FlightMode | None = INITIAL_MODE
    px4_modes: bool = True  # custom_mode in PX4's packing, else ArduPlane's numbers


# Snapshot field -> the bus channel it holds: what the link reads for its streams.
SNAPSHOT_CHANNELS: dict[str, str] = {
    f.name: f.metadata["channel"] for f in fields(Snapshot) if "channel" in f.metadata
}


def snapshot_readers(bus: Any) -> dict[str, Any]:
    """A reader per snapshot field. Telemetry shows a queue's newest sample: a buffer of
    one, not ~1300 copies a second."""
    return {
        key: bus.newest_reader(name)
        if CHANNELS[name].pattern == "queue"
        else bus.latest_reader(name)
        for key, name in SNAPSHOT_CHANNELS.items()
    }
