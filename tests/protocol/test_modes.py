"""Flight modes over MAVLink: both DO_SET_MODE encodings, SET_MODE, the standard modes
protocol, MISSION_START, RTL, go-to; refusals say why."""

from __future__ import annotations

import pytest

from companion.control.mission.mission_files import MissionStore
from companion.control.mission.plan import checked_plan
from companion.control.modes import BY_MODE, MODES
from companion.messages import FlightMode
from mavlink_dialect import companion as m
from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.support.configs import client_vehicle
from tests.support.vehicle import REPO, wait_for

PX4 = {mode: BY_MODE[mode].px4 for mode in FlightMode}


@pytest.fixture
def station(vehicle_factory, tmp_path):
    """A vehicle with the commander, a known position and (unless asked) no mission."""

    def make(with_mission: bool):
        state = tmp_path / "state"
        if with_mission:
            store = MissionStore(state / "missions")
            for kind, items in checked_plan(REPO / "qgc_plans/square.plan").items():
                store.replace(kind, items)
        port = free_udp_port()
        vehicle = vehicle_factory(client_vehicle(f"udpin://127.0.0.1:{port}", state))
        gcs = GroundStation(port)
        gcs.connect()
        made.append(gcs)
        status = vehicle.bus.latest_reader("vehicle/status")
        wait_for(status.get, 60, "the commander's first status")
        # Return needs home, which the commander takes from the navigator's first solution:
        # later than the first status on a busy machine.
        wait_for(lambda: status.get().home_valid, 60, "home from the first solution")
        return vehicle, gcs, status

    made: list[GroundStation] = []
    yield make
    for gcs in made:
        gcs.close()


def heartbeat_mode(gcs: GroundStation, custom: int) -> object:
    return gcs.recv("HEARTBEAT", 5.0, custom_mode=custom)


def test_modes_are_listed_and_reported(station):
    _, gcs, _ = station(with_mission=False)
    beat = heartbeat_mode(gcs, PX4[FlightMode.LOITER])  # a pilotless fixed wing circles
    assert beat.base_mode & m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AVAILABLE_MODES, 0)
    assert gcs.ack(m.MAV_CMD_REQUEST_MESSAGE).result == m.MAV_RESULT_ACCEPTED
    listed = [gcs.recv("AVAILABLE_MODES", 3.0, mode_index=i) for i in range(1, len(MODES) + 1)]
    assert [x.mode_name for x in listed] == [info.name for info in MODES]
    assert {x.number_modes for x in listed} == {len(MODES)}
    # Each its own custom_mode: a tool that names modes by it never shows two as one.
    assert len({x.custom_mode for x in listed}) == len(MODES)
    selectable = {
        x.mode_name for x in listed if not x.properties & m.MAV_MODE_PROPERTY_NOT_USER_SELECTABLE
    }
    assert "Land" not in selectable and {"Hold", "Guided", "Return", "Mission"} <= selectable
    mission = 1 + [info.mode for info in MODES].index(FlightMode.MISSION)
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AVAILABLE_MODES, mission)  # QGC 5.0
    assert gcs.recv("AVAILABLE_MODES", 3.0, mode_index=mission).mode_name == "Mission"
    current = gcs.recv("CURRENT_MODE", 5.0)
    assert current.custom_mode == PX4[FlightMode.LOITER]
    # Our Loiter is automatic: not MAVLink's pilot-driven POSITION_HOLD or ORBIT.
    assert current.standard_mode == m.MAV_STANDARD_MODE_NON_STANDARD


def test_mission_mode_without_a_mission_is_refused_with_a_reason(station):
    _, gcs, status = station(with_mission=False)
    gcs.command(m.MAV_CMD_DO_SET_MODE, m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 10)  # MAVProxy AUTO
    assert gcs.ack(m.MAV_CMD_DO_SET_MODE).result == m.MAV_RESULT_DENIED
    assert "no mission" in gcs.recv("STATUSTEXT", 3.0).text
    gcs.command(m.MAV_CMD_NAV_RETURN_TO_LAUNCH)
    assert gcs.ack(m.MAV_CMD_NAV_RETURN_TO_LAUNCH).result == m.MAV_RESULT_ACCEPTED  # home known
    wait_for(lambda: status.get().mode == FlightMode.RTL, 15, "the commander's status")
    gcs.command(m.MAV_CMD_DO_SET_MODE, m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 99)
    assert gcs.ack(m.MAV_CMD_DO_SET_MODE).result == m.MAV_RESULT_DENIED


@pytest.mark.parametrize(
    ("params", "mode"),
    [
        ((1, 10, 0), FlightMode.MISSION),  # ArduPlane AUTO (pymavlink, MAVProxy)
        ((1, 4, 4), FlightMode.MISSION),  # PX4 AUTO.MISSION (MAVSDK start_mission)
        ((1, 4, 5), FlightMode.RTL),  # PX4 AUTO.RTL (MAVSDK return_to_launch)
        ((1, 0x05040000, 0), FlightMode.RTL),  # a whole PX4 custom_mode
        ((1, 12, 0), FlightMode.LOITER),  # ArduPlane LOITER
        ((1, 11, 0), FlightMode.RTL),  # ArduPlane RTL
        ((1, 7, 0), FlightMode.STABILIZED),  # PX4 STABILIZED
        ((1, 0, 0), FlightMode.MANUAL),  # ArduPlane MANUAL
    ],
)
def test_do_set_mode_in_both_encodings(station, params, mode):
    _, gcs, status = station(with_mission=True)
    gcs.command(m.MAV_CMD_DO_SET_MODE, *params)
    assert gcs.ack(m.MAV_CMD_DO_SET_MODE).result == m.MAV_RESULT_ACCEPTED
    # The commander publishes its status just after the ack: on a busy machine it can come
    # a moment later than the ack reaches the ground station.
    wait_for(lambda: status.get().mode == mode, 15, f"the commander in {mode.name}")
    heartbeat_mode(gcs, PX4[mode])
    assert gcs.recv("CURRENT_MODE", 5.0, custom_mode=PX4[mode])


def test_set_mode_message_standard_modes_mission_start_and_go_to(station):
    _, gcs, status = station(with_mission=True)
    gcs.mav.set_mode_send(1, m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 12)  # the old message
    assert gcs.ack(11).result == m.MAV_RESULT_ACCEPTED
    wait_for(lambda: status.get().mode == FlightMode.LOITER, 15, "the commander's status")
    gcs.command(m.MAV_CMD_DO_SET_STANDARD_MODE, m.MAV_STANDARD_MODE_MISSION)
    assert gcs.ack(m.MAV_CMD_DO_SET_STANDARD_MODE).result == m.MAV_RESULT_ACCEPTED
    wait_for(lambda: status.get().mode == FlightMode.MISSION, 15, "the commander's status")
    gcs.command(m.MAV_CMD_MISSION_START, 2, 0)
    assert gcs.ack(m.MAV_CMD_MISSION_START).result == m.MAV_RESULT_ACCEPTED
    wait_for(lambda: status.get().mission_first == 2, 15, "the commander's status")
    gcs.mav.command_int_send(
        1, 1, m.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, m.MAV_CMD_DO_REPOSITION, 0, 0,
        -1, m.MAV_DO_REPOSITION_FLAGS_CHANGE_MODE, 0, float("nan"),
        -379000000, 1451200000, 50.0,
    )  # fmt: skip
    assert gcs.ack(m.MAV_CMD_DO_REPOSITION).result == m.MAV_RESULT_ACCEPTED
    now = status.get()
    assert now.mode == FlightMode.GUIDED
    assert (now.target_lat_deg, now.target_lon_deg) == (-37.9, 145.12)
    assert now.target_alt_msl_m == pytest.approx(now.home_alt_msl_m + 50.0)
