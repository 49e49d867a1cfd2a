"""The link's command groups against the vehicle as a VehiclePort sees it, in process."""

from __future__ import annotations

import math

from pymavlink.dialects.v20 import common as m

from companion.link.command_service import CommandArgs
from companion.link.commands import ArmingCommands, ModeCommands
from companion.link.microservice import Peer
from companion.messages import CommandId, ControlStatus, VehicleStatus
from tests.support.vehicle_port import RecordingVehicle

GCS = Peer(255, 190, 0)


def args(command: int, *params: float, frame: int = 0) -> CommandArgs:
    full = (*params, *[0.0] * (7 - len(params)))
    return CommandArgs(command, full, 0, GCS, frame=frame)


def flying(vehicle: RecordingVehicle) -> None:
    vehicle.snapshot.control = ControlStatus(landed=0)


def test_disarm_in_the_air_needs_the_force_number():
    vehicle = RecordingVehicle()
    flying(vehicle)
    arming = ArmingCommands(vehicle)
    refused = arming.arm_disarm(args(m.MAV_CMD_COMPONENT_ARM_DISARM, 0))
    assert refused.result == m.MAV_RESULT_DENIED
    assert "Disarm refused" in vehicle.texts[0]
    assert vehicle.published == []
    forced = arming.arm_disarm(args(m.MAV_CMD_COMPONENT_ARM_DISARM, 0, 21196))
    assert forced.defer_seq == 1
    assert vehicle.published == [(CommandId.STOP, ())]
    assert vehicle.texts[-1].startswith("Disarmed in flight (forced)")


def test_arming_is_refused_with_one_prearm_text_per_reason_unless_forced():
    vehicle = RecordingVehicle(prearm=["GPS: no 3D fix", "a", "b", "c"])
    arming = ArmingCommands(vehicle)
    refused = arming.arm_disarm(args(m.MAV_CMD_COMPONENT_ARM_DISARM, 1))
    assert refused.result == m.MAV_RESULT_DENIED and vehicle.published == []
    assert vehicle.texts == ["PreArm: GPS: no 3D fix", "PreArm: a", "PreArm: b"]
    forced = arming.arm_disarm(args(m.MAV_CMD_COMPONENT_ARM_DISARM, 1, 21196))
    assert forced.defer_seq == 1 and vehicle.published == [(CommandId.START, (1.0, 0.0))]


def test_a_disarm_on_the_ground_says_nothing_more():
    vehicle = RecordingVehicle()
    vehicle.snapshot.control = ControlStatus(landed=1)
    ArmingCommands(vehicle).arm_disarm(args(m.MAV_CMD_COMPONENT_ARM_DISARM, 0, 21196))
    assert vehicle.texts == [] and vehicle.published == [(CommandId.STOP, ())]


def test_failure_injection_is_off_until_its_parameter_and_needs_the_simulator():
    vehicle = RecordingVehicle()
    arming = ArmingCommands(vehicle)
    assert arming.inject_failure(args(m.MAV_CMD_INJECT_FAILURE, 1, 1)).result == (
        m.MAV_RESULT_DENIED
    )
    vehicle.params["SYS_FAILURE_EN"] = 1.0
    vehicle.simulated = False
    assert arming.inject_failure(args(m.MAV_CMD_INJECT_FAILURE, 1, 1)).result == (
        m.MAV_RESULT_UNSUPPORTED
    )
    vehicle.simulated = True
    assert arming.inject_failure(args(m.MAV_CMD_INJECT_FAILURE, 1, 1)).defer_seq == 1
    assert vehicle.published == [(CommandId.INJECT_FAILURE, (1.0, 1.0, 0.0))]


def test_mode_commands_without_a_commander_are_unsupported():
    vehicle = RecordingVehicle(commander=False)
    modes = ModeCommands(vehicle, m.MAV_AUTOPILOT_GENERIC)
    assert modes.rtl(args(m.MAV_CMD_NAV_RETURN_TO_LAUNCH)).result == m.MAV_RESULT_UNSUPPORTED
    assert vehicle.published == []


def test_go_to_without_a_point_pauses_and_relative_heights_are_over_the_commanders_home():
    vehicle = RecordingVehicle()
    modes = ModeCommands(vehicle, m.MAV_AUTOPILOT_PX4)
    # QGroundControl's Pause (PX4FirmwarePlugin::pauseVehicle): no point, no height.
    pause = modes.reposition(args(m.MAV_CMD_DO_REPOSITION, -1, 1, 0, *[math.nan] * 4))
    assert pause.defer_seq == 1
    assert vehicle.texts == []
    here = vehicle.published[0]
    assert here[0] == CommandId.REPOSITION and all(math.isnan(v) for v in here[1])
    vehicle.published.clear()
    status = VehicleStatus(home_valid=1, home_alt_msl_m=50.0)
    vehicle.snapshot.status = status
    relative = m.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    there = modes.reposition(
        args(m.MAV_CMD_DO_REPOSITION, -1, 0, 0, math.nan, -37.9, 145.1, 100, frame=relative)
    )
    assert there.defer_seq == 1
    assert vehicle.published == [(CommandId.REPOSITION, (-37.9, 145.1, 150.0))]
