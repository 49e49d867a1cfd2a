"""Every bus message type and the CHANNELS table: the one registry of the vehicle's data.

Each payload is a fixed-size ctypes structure, so it can live in iceoryx2 shared memory.
Field names carry their units; ``t_us`` (first field of every type) is the time the data
was measured in the vehicle time base (monotonic µs on hardware, simulation µs in SITL).
"Not set" for a float is NaN. Frames: body is FRD, navigation is local NED.

The types are split by pipeline stage (sensors, navigation, control, actuators, link,
system, simulation); ``channels.py`` holds the one CHANNELS table. Import from here.
"""

from companion.messages.actuators import ActuatorCommand, CameraCapture, ServoOutput
from companion.messages.base import MAX_PLUGINS, NAME_LEN, NAN, Message
from companion.messages.channels import CHANNELS, Channel, channel
from companion.messages.control import (
    ACTUATOR_SEQ,
    CAMERA_SEQ,
    GRIPPER_SEQ,
    MISSION_HOME_SEQ,
    MISSION_SERVO_SEQ,
    REASON_LEN,
    CommandAck,
    CommandId,
    CommandResult,
    ControlStatus,
    FlightMode,
    LandPhase,
    MissionState,
    TakeoffPhase,
    VehicleCommand,
    VehicleStatus,
)
from companion.messages.link import (
    RTCM_MAX_BYTES,
    GpsInject,
    LinkStatus,
    MissionChanged,
    StatusText,
)
from companion.messages.navigation import NavFlags, NavState
from companion.messages.pilot import RC_MAX_CHANNELS, PilotFlags, PilotInput, PilotSource
from companion.messages.sensors import (
    Baro,
    Battery,
    BatteryLevel,
    Compass,
    GpsFix,
    GpsFixType,
    Imu,
    Magnetometer,
    RangeReading,
)
from companion.messages.simulation import SimClock, SimTruth
from companion.messages.system import (
    LogProgress,
    ParamChange,
    PluginHealth,
    PluginState,
    PluginStats,
    SystemHealth,
)

__all__ = [
    "ACTUATOR_SEQ",
    "CAMERA_SEQ",
    "CHANNELS",
    "GRIPPER_SEQ",
    "MAX_PLUGINS",
    "MISSION_HOME_SEQ",
    "MISSION_SERVO_SEQ",
    "NAME_LEN",
    "NAN",
    "RC_MAX_CHANNELS",
    "REASON_LEN",
    "RTCM_MAX_BYTES",
    "ActuatorCommand",
    "Baro",
    "Battery",
    "BatteryLevel",
    "CameraCapture",
    "Channel",
    "CommandAck",
    "CommandId",
    "CommandResult",
    "Compass",
    "ControlStatus",
    "FlightMode",
    "GpsFix",
    "GpsFixType",
    "GpsInject",
    "Imu",
    "LandPhase",
    "LinkStatus",
    "LogProgress",
    "Magnetometer",
    "Message",
    "MissionChanged",
    "MissionState",
    "NavFlags",
    "NavState",
    "ParamChange",
    "PilotFlags",
    "PilotInput",
    "PilotSource",
    "PluginHealth",
    "PluginState",
    "PluginStats",
    "RangeReading",
    "ServoOutput",
    "SimClock",
    "SimTruth",
    "StatusText",
    "SystemHealth",
    "TakeoffPhase",
    "VehicleCommand",
    "VehicleStatus",
    "channel",
]
