"""The MAV_CMDs the link answers, one class per group of commands.

Each group sees the vehicle only through ``VehiclePort`` (publish a command on the bus,
tell the operator, read the telemetry snapshot and a parameter), so it is tested and
read without the link plug-in; ``register_commands`` wires every group into the
command service.
"""

from __future__ import annotations

from companion.link.calibration_service import Calibration
from companion.link.command_rules import RULES, refusal
from companion.link.command_service import CommandService
from companion.link.commands.arming import ArmingCommands
from companion.link.commands.calibration import CalibrationCommands
from companion.link.commands.camera_commands import CameraCommands
from companion.link.commands.fence_commands import FenceCommands
from companion.link.commands.message_requests import MessageRequests
from companion.link.commands.mission_commands import MissionCommands
from companion.link.commands.mode_commands import ModeCommands
from companion.link.commands.port import BUS_ACK_TIMEOUT_S, VehiclePort
from companion.link.commands.servo_commands import ServoCommands
from companion.link.commands.speed_commands import SpeedCommands
from companion.link.commands.storage import StorageCommands
from companion.link.identity import IdentityService
from companion.link.link_router import LinkRouter
from companion.link.metadata_service import MetadataService
from companion.link.mission_service import MissionService
from companion.link.params_service import ParamsService

__all__ = [
    "BUS_ACK_TIMEOUT_S",
    "ArmingCommands",
    "CalibrationCommands",
    "CameraCommands",
    "FenceCommands",
    "MessageRequests",
    "MissionCommands",
    "ModeCommands",
    "ServoCommands",
    "SpeedCommands",
    "StorageCommands",
    "VehiclePort",
    "register_commands",
]


def register_commands(
    service: CommandService,
    port: VehiclePort,
    identity: IdentityService,
    router: LinkRouter,
    metadata: MetadataService | None = None,
    params: ParamsService | None = None,
    missions: MissionService | None = None,
) -> None:
    """Register every supported MAV_CMD with ``service``, behind the parameter rules (the
    sensor calibrations when there are parameters to keep their results). A command
    without a rule in ``command_rules.RULES`` cannot be registered."""
    service.guard(refusal, RULES)
    service.on_refusal = port.statustext
    ArmingCommands(port).register(service)
    ModeCommands(port, identity.autopilot).register(service)
    SpeedCommands(port, params).register(service)
    ServoCommands(port).register(service)
    CameraCommands(port).register(service)
    FenceCommands(port, params).register(service)
    MessageRequests(port, identity, router, metadata).register(service)
    if missions is not None:
        MissionCommands(port, missions).register(service)
    if params is not None:
        calibration = Calibration(port, params)
        CalibrationCommands(port, calibration).register(service)
        StorageCommands(port, params, calibration).register(service)
        router.add_service(calibration)
