"""The CHANNELS table: every bus channel by name, with its payload type, pattern and depth."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from companion.messages.actuators import ActuatorCommand, CameraCapture, ServoOutput
from companion.messages.base import Message
from companion.messages.control import CommandAck, ControlStatus, VehicleCommand, VehicleStatus
from companion.messages.link import GpsInject, LinkStatus, MissionChanged, StatusText
from companion.messages.navigation import NavState
from companion.messages.pilot import PilotInput
from companion.messages.sensors import (
    Baro,
    Battery,
    Compass,
    GpsFix,
    Imu,
    Magnetometer,
    RangeReading,
)
from companion.messages.simulation import SimClock, SimTruth
from companion.messages.system import LogProgress, ParamChange, PluginStats, SystemHealth


@dataclass(frozen=True)
class Channel:
    """A named bus channel: its payload type and pattern (and depth for queues)."""

    name: str
    type: type[Message]
    pattern: Literal["queue", "latest"]
    # A queue's depth; for a latest channel, how many values a reader may ask to keep
    # between its reads (the flight log keeps every one; other readers keep the newest).
    depth: int = 1
    doc: str = ""
    many_producers: bool = False  # every plug-in may publish (e.g. system/plugin_stats)
    # Why the flight log leaves this channel out by default ("": it records it). A new
    # channel is recorded unless it says here why not.
    unlogged: str = ""


# Latest channels that change at up to 100 Hz keep this many values for a reader that
# asks: the flight log, woken every 0.1 s, records each one. 64 is 0.64 s at 100 Hz, as the
# IMU's queue holds: room for a late wake-up on a busy machine (32 held 0.32 s, and the
# logger lost 3 rangefinder readings of 2399 with the machine at load 11 on two cores;
# 16 held 0.16 s, and the logger, keeping a queue under a quarter full, read 24 times a
# second).
KEEP = 64


def _channels(*chans: Channel) -> dict[str, Channel]:
    return {c.name: c for c in chans}


CHANNELS: dict[str, Channel] = _channels(
    Channel("sensors/imu", Imu, "queue", 64, "raw IMU samples"),
    Channel("sensors/mag", Magnetometer, "queue", 32, "raw magnetometer samples"),
    Channel("sensors/gps", GpsFix, "queue", 8, "GPS fixes"),
    Channel("sensors/compass", Compass, "queue", 32, "digital compass attitude"),
    Channel("sensors/baro", Baro, "queue", 32, "barometric altitude"),
    Channel("sensors/range", RangeReading, "latest", KEEP, doc="downward rangefinder's reading"),
    Channel("sensors/rc", PilotInput, "latest", KEEP, doc="the RC receiver's newest frame"),
    Channel(
        "sensors/rc_switch",
        PilotInput,
        "queue",
        8,
        "frames where the mode switch moved",
        unlogged="every receiver frame is in sensors/rc already",
    ),
    Channel("link/manual_control", PilotInput, "latest", KEEP, doc="the ground station's joystick"),
    Channel(
        "link/gps_inject",
        GpsInject,
        "queue",
        16,
        "RTCM corrections from the ground station, for the GPS receiver",
        unlogged="the base station's own data, up to 720 bytes a message, several a second",
    ),
    Channel(
        "sensors/battery", Battery, "latest", KEEP, doc="flight battery voltage, current, charge"
    ),
    Channel("nav/state", NavState, "latest", KEEP, doc="navigation solution"),
    Channel(
        "sim/truth",
        SimTruth,
        "latest",
        doc="simulator's true state",
        unlogged="the simulator's, not the vehicle's (companion sim --truth writes it)",
    ),
    Channel(
        "sim/clock",
        SimClock,
        "latest",
        doc="simulation time",
        unlogged="every sample's t_us is on the simulation's clock already",
    ),
    Channel("vehicle/status", VehicleStatus, "latest", KEEP, doc="mode, home, guided target"),
    # 32 at 50 Hz: 0.64 s, for the flight log's 0.1 s reads (the servos take the newest).
    Channel("control/actuators", ActuatorCommand, "queue", 32, "normalised surfaces"),
    Channel("control/status", ControlStatus, "latest", KEEP, doc="guidance and mission progress"),
    Channel("actuators/servos", ServoOutput, "latest", KEEP, doc="servo outputs written"),
    # Recorded as the flight log's topic camera_capture, which geotagging tools read.
    Channel("camera/capture", CameraCapture, "queue", 16, "photos taken, with their position"),
    Channel("link/commands", VehicleCommand, "queue", 16, "commands for the vehicle", True),
    Channel("link/command_acks", CommandAck, "queue", 16, "command outcomes"),
    Channel(
        "system/plugin_stats",
        PluginStats,
        "queue",
        64,
        "per-plug-in counters",
        True,
        unlogged="system/health, recorded, carries every plug-in's counters",
    ),
    Channel("system/health", SystemHealth, "latest", doc="the health table"),
    Channel(
        "system/logged",
        LogProgress,
        "latest",
        doc="how far the flight log has written",
        unlogged="the flight log's own progress",
    ),
    Channel("params/changes", ParamChange, "queue", 32, "parameters set from the ground"),
    Channel("link/status", LinkStatus, "latest", doc="ground-station heartbeats heard"),
    Channel("mission/changed", MissionChanged, "latest", doc="stored mission lists changed"),
    Channel("vehicle/statustext", StatusText, "queue", 16, "messages for the operator", True),
)


# What the flight log records unless its config names other channels.
LOGGED: tuple[str, ...] = tuple(name for name, c in CHANNELS.items() if not c.unlogged)


def channel(name: str) -> Channel:
    """The registered channel of that name; KeyError names the unknown channel."""
    try:
        return CHANNELS[name]
    except KeyError:
        raise KeyError(f"unknown bus channel {name!r}; known: {sorted(CHANNELS)}") from None
