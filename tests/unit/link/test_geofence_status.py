"""SYS_STATUS's geofence bits as ArduPilot sets them (MAVProxy said "fence breach" at every
connect while they were 0), and DO_FENCE_ENABLE as a write of FENCE_ENABLE."""

from __future__ import annotations

import math

from pymavlink.dialects.v20 import common as m

from companion.control.failsafe import FAILSAFE_PARAMS
from companion.control.mission.fence import Fence
from companion.control.mission.items import MissionItem
from companion.link.codec import new_encoder
from companion.link.command_rules import RULES, refusal
from companion.link.command_service import CommandArgs, CommandService
from companion.link.commands import FenceCommands
from companion.link.microservice import Peer
from companion.link.params_service import ParamsService
from companion.link.snapshot import Snapshot
from companion.link.telemetry import STREAMS
from companion.messages import NavFlags, NavState
from companion.params import ParamStore
from tests.support.vehicle_port import RecordingVehicle

GCS = Peer(255, 190, 0)
BIT = m.MAV_SYS_STATUS_GEOFENCE
LAT, LON = -37.9105, 145.134


def _circle(radius_m: float) -> Fence:
    item = MissionItem(0, m.MAV_FRAME_GLOBAL, m.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION, 0, 1,
                       radius_m, 0, 0, 0, round(LAT * 1e7), round(LON * 1e7), 0.0, 1)  # fmt: skip
    return Fence.from_items([item])


def _bits(snap: Snapshot) -> tuple[int, int, int]:
    msg = STREAMS[m.MAVLINK_MSG_ID_SYS_STATUS].build(new_encoder(1), snap)
    return (
        msg.onboard_control_sensors_present & BIT,
        msg.onboard_control_sensors_enabled & BIT,
        msg.onboard_control_sensors_health & BIT,
    )


def test_present_with_a_fence_enabled_with_fence_enable_healthy_unless_breached():
    nav = NavState(t_us=1, lat_deg=LAT, lon_deg=LON, flags=int(NavFlags.POSITION_VALID))
    snap = Snapshot(nav=nav)
    assert _bits(snap) == (0, 0, BIT)  # no fence: healthy, so MAVProxy says nothing
    snap.fence = _circle(500.0)
    assert _bits(snap) == (BIT, 0, BIT)  # stored, FENCE_ENABLE 0
    snap.fence_enabled = True
    assert _bits(snap) == (BIT, BIT, BIT)  # inside it
    snap.fence = _circle(500.0)
    nav.lat_deg = LAT + 0.01  # 1.1 km north: outside
    assert _bits(snap) == (BIT, BIT, 0)
    snap.fence_enabled = False  # a breach of a disabled fence is no failure (ArduPilot)
    assert _bits(snap) == (BIT, 0, BIT)
    snap.fence_enabled, nav.lat_deg = True, math.nan  # no position: nothing breached
    assert _bits(snap) == (BIT, BIT, BIT)


def _fence_bench() -> tuple[CommandService, RecordingVehicle, ParamsService]:
    mav = new_encoder(1, 1)
    service = CommandService(mav, 1, 1)
    service.guard(refusal, RULES)
    vehicle = RecordingVehicle()
    service.on_refusal = vehicle.statustext
    params = ParamsService(mav, ParamStore(FAILSAFE_PARAMS), 1, 1)
    FenceCommands(vehicle, params).register(service)
    return service, vehicle, params


def _send(service: CommandService, *params: float) -> list:
    full = (*params, *[0.0] * (7 - len(params)))
    return service.dispatch(CommandArgs(m.MAV_CMD_DO_FENCE_ENABLE, full, 0, GCS), 0.0)


def test_fence_enable_writes_the_parameter_and_tells_every_station():
    service, vehicle, params = _fence_bench()
    changed: list[tuple[str, float]] = []
    params.on_change = lambda name, value: changed.append((name, value))
    ack, value = _send(service, 0)
    assert ack.msg.result == m.MAV_RESULT_ACCEPTED and ack.to == GCS
    assert value.msg.get_type() == "PARAM_VALUE" and value.to is None  # every station
    assert (value.msg.param_id, value.msg.param_value) == ("FENCE_ENABLE", 0.0)
    assert params.store.get("FENCE_ENABLE") == 0.0 and changed == [("FENCE_ENABLE", 0.0)]
    assert vehicle.texts == ["Fence disabled"]
    assert _send(service, 1)[0].msg.result == m.MAV_RESULT_ACCEPTED
    assert params.store.get("FENCE_ENABLE") == 1.0


def test_hostile_or_floor_only_fence_commands_are_denied_and_change_nothing():
    service, vehicle, params = _fence_bench()
    for bad in (2, math.nan, math.inf, -1, 3, 0.5):
        (ack,) = _send(service, bad)
        assert ack.msg.result == m.MAV_RESULT_DENIED
    assert service.refused == 6 and params.store.get("FENCE_ENABLE") == 1.0
    assert "no floor" in vehicle.texts[0]
    without = CommandService(new_encoder(1, 1), 1, 1)
    FenceCommands(vehicle, None).register(without)
    (ack,) = _send(without, 0)
    assert ack.msg.result == m.MAV_RESULT_UNSUPPORTED
