"""Property tests: any value in any field of what the vehicle accepts, in process.

Every command gets exactly one answer and no handler raises; refused missions and
parameters leave what was stored untouched; the commander never crashes or takes a
target that is not a place on Earth.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from companion.control.commander import Commander
from companion.control.mission.items import MissionItem, check_mission
from companion.control.mission.mission_files import MissionStore
from companion.link.codec import new_encoder
from companion.link.command_rules import RULES
from companion.link.command_service import CommandService
from companion.link.commands import register_commands
from companion.link.endpoints import open_endpoint
from companion.link.identity import IdentityService
from companion.link.link_router import LinkRouter
from companion.link.microservice import Peer
from companion.link.mission_service import MissionService
from companion.link.params_service import ParamsService
from companion.messages import CommandId, VehicleCommand
from companion.params import ParamDecl, ParamStore
from companion.sensors.imu_calibration import IMU_CAL_PARAMS
from mavlink_dialect import companion as d
from tests.support.vehicle_port import RecordingVehicle

GCS = Peer(255, 190, 0)
ANY_FLOAT = st.floats(allow_nan=True, allow_infinity=True, width=32)
EDGE_FLOATS = st.sampled_from([0.0, 1.0, -1.0, 21196.0, 1e7, -1e9, 3.4e38, math.nan, math.inf])
PARAM = st.one_of(ANY_FLOAT, EDGE_FLOATS)
INT32 = st.integers(-(2**31), 2**31 - 1)
COMMAND = st.one_of(st.sampled_from(sorted(RULES)), st.integers(0, 65535))
FAST = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@contextmanager
def command_service() -> Iterator[tuple[CommandService, RecordingVehicle]]:
    """The link's command service with every group registered, one real UDP endpoint."""
    mav = new_encoder(1, 1)
    identity = IdentityService(mav, 1, d.MAV_AUTOPILOT_GENERIC, 0)
    endpoint = open_endpoint("udpout://127.0.0.1:9")  # never written to here
    router = LinkRouter(mav, [endpoint], [], None)
    service = CommandService(mav, 1, 1)
    vehicle = RecordingVehicle()
    params = ParamsService(mav, ParamStore(IMU_CAL_PARAMS), 1, 1)  # the IMU's calibration
    missions = MissionService(mav, MissionStore(None), 1, 1)  # three items, in memory
    waypoint = MissionItem(0, 3, d.MAV_CMD_NAV_WAYPOINT, 0, 1, 0, 0, 0, 0, 0, 0, 50.0)
    missions.store.replace(0, [waypoint, waypoint, waypoint])
    register_commands(service, vehicle, identity, router, None, params, missions)
    try:
        yield service, vehicle
    finally:
        endpoint.close()


def acks_in(out) -> list:
    return [o.msg for o in out if o.msg.get_type() == "COMMAND_ACK"]


@FAST
@given(
    command=COMMAND,
    params=st.lists(PARAM, min_size=7, max_size=7),
    as_int=st.booleans(),
    x=INT32,
    y=INT32,
    frame=st.integers(0, 21),
    flying=st.booleans(),
)
def test_every_command_gets_exactly_one_answer_and_no_handler_raises(
    command, params, as_int, x, y, frame, flying
):
    with command_service() as (service, vehicle):
        answer_one(service, vehicle, command, params, as_int, x, y, frame, flying)


def answer_one(service, vehicle, command, params, as_int, x, y, frame, flying) -> None:
    mav = service.mav
    if flying:
        from companion.messages import ControlStatus

        vehicle.snapshot.control = ControlStatus(landed=0)
    if as_int:
        msg = mav.command_int_encode(1, 1, frame, command, 0, 0, *params[:4], x, y, params[6])
    else:
        msg = mav.command_long_encode(1, 1, command, 0, *params)
    out = service.handle(msg, GCS, 100.0)
    out += service.tick(200.0)  # a command handed to the bus and never answered: FAILED
    acks = acks_in(out)
    assert len(acks) == 1 and acks[0].command == command
    assert service.handler_errors == 0
    if acks[0].result == d.MAV_RESULT_DENIED and service.refused:
        assert vehicle.published == []  # refused input never reaches the vehicle
    for _, published in vehicle.published:
        assert not any(math.isinf(v) for v in published)


@FAST
@given(base=st.integers(0, 255), custom=st.integers(0, 2**32 - 1))
def test_the_old_set_mode_message_is_always_answered(base, custom):
    with command_service() as (service, _):
        out = service.handle(service.mav.set_mode_encode(1, base, custom), GCS, 1.0)
        out += service.tick(100.0)
        assert len(acks_in(out)) == 1
        assert service.handler_errors == 0


@FAST
@given(command=st.sampled_from(list(CommandId)), params=st.lists(PARAM, min_size=7, max_size=7))
def test_the_commander_never_raises_nor_targets_what_is_not_a_place(command, params):
    commander = Commander(lambda: 3)
    commander.position = (-37.9, 145.1, 100.0)
    commander.home = commander.position
    cmd = VehicleCommand(command=int(command))
    for i, value in enumerate(params):
        cmd.param[i] = value
    commander.handle(cmd)
    lat, lon, alt = commander.target
    assert math.isnan(lat) or (abs(lat) <= 90 and abs(lon) <= 180)
    assert not math.isinf(alt)
    home_lat, home_lon, home_alt = commander.home
    assert abs(home_lat) <= 90 and abs(home_lon) <= 180 and math.isfinite(home_alt)
    assert commander.mission_first >= 0


ITEM_COMMANDS = st.sampled_from(
    [
        d.MAV_CMD_NAV_WAYPOINT,
        d.MAV_CMD_NAV_TAKEOFF,
        d.MAV_CMD_NAV_LOITER_TIME,
        d.MAV_CMD_NAV_LOITER_TURNS,
        d.MAV_CMD_DO_JUMP,
        d.MAV_CMD_DO_CHANGE_SPEED,
        d.MAV_CMD_NAV_LAND,
    ]
)
ITEM = st.tuples(
    ITEM_COMMANDS, st.integers(0, 12), st.lists(PARAM, min_size=5, max_size=5), INT32, INT32
)


def _known_mission() -> list[MissionItem]:
    wp = d.MAV_CMD_NAV_WAYPOINT
    return [
        MissionItem(i, 3, wp, 0, 1, 0, 0, 0, math.nan, -379000000 + i, 1451000000, 100.0)
        for i in range(3)
    ]


@settings(
    max_examples=150,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
@given(items=st.lists(ITEM, min_size=1, max_size=4), legacy=st.booleans())
def test_a_refused_mission_leaves_the_stored_one_untouched(tmp_path, items, legacy):
    store = MissionStore(None)
    store.replace(0, _known_mission())
    before = list(store.items[0])
    mav = new_encoder(1, 1)
    service = MissionService(mav, store, 1, 1)
    out = service.handle(mav.mission_count_encode(1, 1, len(items), 0), GCS, 0.0)
    for seq, (command, frame, p, x, y) in enumerate(items):
        if legacy:
            msg = mav.mission_item_encode(1, 1, seq, frame, command, 0, 1, *p[:4], p[4], p[0], p[1])
        else:
            msg = mav.mission_item_int_encode(1, 1, seq, frame, command, 0, 1, *p[:4], x, y, p[4])
        out += service.handle(msg, GCS, 0.0)
    acks = [o.msg for o in out if o.msg.get_type() == "MISSION_ACK"]
    assert len(acks) == 1
    if acks[0].type == d.MAV_MISSION_ACCEPTED:
        assert check_mission(store.items[0]) == d.MAV_MISSION_ACCEPTED
        assert len(store.items[0]) == len(items)
    else:
        assert store.items[0] == before


DECLS = (
    ParamDecl("SR_ATTITUDE", 10.0, 0.0, 100.0, "Hz"),
    ParamDecl("TRIM_ARSPD", 22.0, 10.0, 60.0, "m/s"),
)


@FAST
@given(name=st.sampled_from(["SR_ATTITUDE", "TRIM_ARSPD", "NOPE", ""]), value=PARAM)
def test_a_refused_parameter_keeps_its_value_and_is_echoed(name, value):
    store = ParamStore(DECLS, None)
    mav = new_encoder(1, 1)
    texts: list[str] = []
    service = ParamsService(mav, store, 1, 1, on_refusal=texts.append)
    before = {decl.name: store.get(decl.name) for decl in DECLS}
    out = service.handle(mav.param_set_encode(1, 1, name.encode(), value, 9), GCS, 0.0)
    for decl in DECLS:
        now = store.get(decl.name)
        assert math.isfinite(now) and decl.min <= now <= decl.max
        if decl.name != name:
            assert now == before[decl.name]
    if name in before:
        assert [o.msg.param_id for o in out] == [name]
        if not (math.isfinite(value) and store.decls[name].check(value) is None):
            assert store.get(name) == before[name] and texts
