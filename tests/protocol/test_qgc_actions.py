"""QGroundControl's Fly-view actions, sent exactly as its PX4 firmware plug-in sends them.

The vehicle reports MAV_AUTOPILOT_PX4 and MAV_TYPE_FIXED_WING, so QGroundControl 4.4 and 5
load src/FirmwarePlugin/PX4/PX4FirmwarePlugin.cc, whose isCapable() offers Takeoff, Pause,
guided actions and Orbit for a fixed wing; src/FlightDisplay/GuidedActionsController.qml
decides when each is shown (Land never, for a fixed wing). What each action sends:
- Takeoff: PX4FirmwarePlugin::guidedModeTakeoff, COMMAND_LONG NAV_TAKEOFF (param1 -1,
  param5/6 NaN, param7 = altitude AMSL), then arms once it is accepted (_mavCommandResult);
- Start Mission / Continue Mission: PX4FirmwarePlugin::startMission, the "Mission" mode
  (Vehicle::setFlightMode: DO_SET_MODE with base mode CUSTOM_MODE_ENABLED and the whole
  custom_mode, as MAV_CMD_DO_SET_MODE_is_supported() is true for PX4), validated by the
  heartbeat, then arming;
- Pause: PX4FirmwarePlugin::pauseVehicle, DO_REPOSITION (-1, CHANGE_MODE, 0, NaN x4);
- Change altitude: guidedModeChangeAltitude, DO_REPOSITION with NaN yaw/lat/lon and the
  new altitude AMSL (after a pause when asked);
- Go to location: guidedModeGotoLocation, COMMAND_INT DO_REPOSITION in MAV_FRAME_GLOBAL with
  the vehicle's present altitude AMSL (COMMAND_INT because AUTOPILOT_VERSION says so);
- Orbit: FirmwarePlugin::guidedModeOrbit, COMMAND_INT DO_ORBIT (radius, NaN, NaN, NaN,
  lat, lon, altitude AMSL) in MAV_FRAME_GLOBAL;
- Return: guidedModeRTL, the "Return" mode, validated by the heartbeat;
- Land Abort (shown for a fixed wing only while EXTENDED_SYS_STATE says LANDING):
  Vehicle::abortLanding(50), COMMAND_LONG DO_GO_AROUND with param1 = 50 (the altitude).
QGroundControl 5 also asks AVAILABLE_MODES (src/Vehicle/StandardModes.cc, all at once with
param2 = 0) and names modes PX4 does not know from it.
"""

from __future__ import annotations

import math

import pytest

from companion.control.mission.mission_files import MissionStore
from companion.control.mission.plan import checked_plan
from companion.control.modes import BY_MODE
from companion.messages import FlightMode
from mavlink_dialect import companion as m
from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.support.configs import FAKE_APPROACH, client_vehicle, plugin
from tests.support.plugins import FakeNav
from tests.support.vehicle import REPO, wait_for

NAN = math.nan
CHANGE_MODE = m.MAV_DO_REPOSITION_FLAGS_CHANGE_MODE
FORCE = 21196  # only to disarm a vehicle the stand-in navigator says is moving


@pytest.fixture
def qgc(vehicle_factory, tmp_path):
    state = tmp_path / "state"
    store = MissionStore(state / "missions")
    for kind, items in checked_plan(REPO / "qgc_plans/square.plan").items():
        store.replace(kind, items)
    port = free_udp_port()
    vehicle = vehicle_factory(client_vehicle(f"udpin://127.0.0.1:{port}", state))
    gcs = GroundStation(port)  # sysid 255, compid 190, as QGroundControl
    first = gcs.connect()
    status = vehicle.bus.latest_reader("vehicle/status")
    # The commander has a position and a home (on a busy machine the navigator's first
    # solution can come late, and Go to and Return would be refused until then).
    wait_for(lambda: (s := status.get()) is not None and s.home_valid, 60, "a home position")
    yield gcs, status, first
    gcs.close()


def set_mode(gcs: GroundStation, mode: FlightMode) -> int:
    """Vehicle::setFlightMode for the PX4 plug-in; the result of its DO_SET_MODE."""
    gcs.command(m.MAV_CMD_DO_SET_MODE, m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, BY_MODE[mode].px4)
    return gcs.ack(m.MAV_CMD_DO_SET_MODE).result


def shown(gcs: GroundStation, mode: FlightMode) -> None:
    """_setFlightModeAndValidate: QGroundControl waits for the heartbeat to show the mode."""
    gcs.recv("HEARTBEAT", 15.0, custom_mode=BY_MODE[mode].px4)


def arm(gcs: GroundStation, on: bool, force: bool = False) -> int:
    gcs.command(m.MAV_CMD_COMPONENT_ARM_DISARM, int(on), FORCE if force else 0)
    return gcs.ack(m.MAV_CMD_COMPONENT_ARM_DISARM).result


def wait_armable(gcs: GroundStation, status) -> None:
    """QGroundControl's arm is refused until the pre-arm checks pass (GPS fix first)."""
    healthy = m.MAV_SYS_STATUS_PREARM_CHECK
    wait_for(lambda: gcs.recv("SYS_STATUS", 5.0).onboard_control_sensors_health & healthy, 30,
             "pre-arm checks passing")  # fmt: skip


def settled(status, check, what: str):
    """The commander's status once it shows ``check`` (it is published just after the ack)."""
    wait_for(lambda: check(status.get()), 15, what)
    return status.get()


def reposition(gcs: GroundStation, lat: float, lon: float, alt: float) -> int:
    """COMMAND_LONG DO_REPOSITION, as pauseVehicle and guidedModeChangeAltitude send it."""
    gcs.command(m.MAV_CMD_DO_REPOSITION, -1, CHANGE_MODE, 0, NAN, lat, lon, alt)
    return gcs.ack(m.MAV_CMD_DO_REPOSITION).result


def command_int(gcs: GroundStation, command: int, *params: float, lat: float, lon: float,
                alt: float) -> int:  # fmt: skip
    gcs.mav.command_int_send(1, 1, m.MAV_FRAME_GLOBAL, command, 0, 0, *params,
                             round(lat * 1e7), round(lon * 1e7), alt)  # fmt: skip
    return gcs.ack(command).result


def test_first_heartbeat_names_a_mode_and_qgc5_reads_every_mode(qgc):
    gcs, _, first = qgc
    assert first.autopilot == m.MAV_AUTOPILOT_PX4 and first.type == m.MAV_TYPE_FIXED_WING
    # PX4FirmwarePlugin::flightMode names exactly its own custom_modes: never "Unknown 0".
    assert first.custom_mode == BY_MODE[FlightMode.LOITER].px4
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AVAILABLE_MODES, 0)
    assert gcs.ack(m.MAV_CMD_REQUEST_MESSAGE).result == m.MAV_RESULT_ACCEPTED
    count = len(BY_MODE)
    modes = [gcs.recv("AVAILABLE_MODES", 3.0, mode_index=i) for i in range(1, count + 1)]
    by_name = {x.mode_name: x for x in modes}
    guided = by_name["Guided"]
    # QGroundControl 5 (FirmwarePlugin::_updateFlightModeList) keeps PX4's names for PX4's
    # custom_modes and takes ours for the rest: Guided must not collide with any of them.
    assert guided.custom_mode not in {x.custom_mode for x in modes if x is not guided}
    assert guided.standard_mode == m.MAV_STANDARD_MODE_NON_STANDARD  # keeps its own name
    # Not SAFE_RECOVERY: QGroundControl 4.4.5 would name it "Safe Recovery" and its Return
    # button, asking for "Return", would find nothing (tests/protocol/test_qgc_mode_lookup.py).
    assert by_name["Return"].standard_mode == m.MAV_STANDARD_MODE_NON_STANDARD


def test_takeoff_then_arm_as_qgroundcontrol_does(qgc):
    gcs, status, _ = qgc
    wait_armable(gcs, status)
    target = FakeNav.ALT + 40.0  # the slider's 40 m above the vehicle, AMSL
    gcs.command(m.MAV_CMD_NAV_TAKEOFF, -1, 0, 0, NAN, NAN, NAN, target)
    assert gcs.ack(m.MAV_CMD_NAV_TAKEOFF).result == m.MAV_RESULT_ACCEPTED
    shown(gcs, FlightMode.TAKEOFF)
    settled(status, lambda s: s.target_alt_msl_m == pytest.approx(target), "take-off height")
    assert arm(gcs, True) == m.MAV_RESULT_ACCEPTED  # _mavCommandResult arms on the accept
    beat = gcs.recv("HEARTBEAT", 5.0, custom_mode=BY_MODE[FlightMode.TAKEOFF].px4)
    wait_for(lambda: status.get().armed, 5, "armed in Takeoff")
    assert beat.base_mode & m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
    assert arm(gcs, False, force=True) == m.MAV_RESULT_ACCEPTED


def test_start_mission_then_every_in_flight_action(qgc):
    gcs, status, _ = qgc
    wait_armable(gcs, status)
    # Start Mission: the mode first, checked on the heartbeat, then arming.
    assert set_mode(gcs, FlightMode.MISSION) == m.MAV_RESULT_ACCEPTED
    shown(gcs, FlightMode.MISSION)
    assert arm(gcs, True) == m.MAV_RESULT_ACCEPTED
    # Pause: Loiter here (PX4's "Hold", QGroundControl's pauseFlightMode).
    assert reposition(gcs, NAN, NAN, NAN) == m.MAV_RESULT_ACCEPTED
    shown(gcs, FlightMode.LOITER)
    here = settled(status, lambda s: s.mode == FlightMode.LOITER, "paused")
    assert (here.target_lat_deg, here.target_lon_deg) == pytest.approx((FakeNav.LAT, FakeNav.LON))
    # Change altitude: the same circle, 30 m higher.
    assert reposition(gcs, NAN, NAN, FakeNav.ALT + 70.0) == m.MAV_RESULT_ACCEPTED
    higher = settled(status, lambda s: s.target_alt_msl_m == FakeNav.ALT + 70.0, "climbing")
    assert higher.mode == FlightMode.LOITER
    assert higher.target_lat_deg == pytest.approx(FakeNav.LAT)
    # Go to location (a click on the map): Guided, its own mode and name. QGroundControl
    # sends the vehicle's present altitude: on the stand-in's ground, under the floor
    # (GUIDED_ALT_MIN above home), so refused with the reason; in flight, accepted.
    lat, lon = FakeNav.LAT + 0.004, FakeNav.LON + 0.003
    low = command_int(gcs, m.MAV_CMD_DO_REPOSITION, -1, CHANGE_MODE, 0, NAN,
                      lat=lat, lon=lon, alt=FakeNav.ALT)  # fmt: skip
    assert low == m.MAV_RESULT_DENIED
    assert "below GUIDED_ALT_MIN" in gcs.recv("STATUSTEXT", 3.0).text
    go = command_int(gcs, m.MAV_CMD_DO_REPOSITION, -1, CHANGE_MODE, 0, NAN,
                     lat=lat, lon=lon, alt=FakeNav.ALT + 80.0)  # fmt: skip
    assert go == m.MAV_RESULT_ACCEPTED
    shown(gcs, FlightMode.GUIDED)
    there = settled(status, lambda s: s.mode == FlightMode.GUIDED, "going")
    assert (there.target_lat_deg, there.target_lon_deg) == pytest.approx((lat, lon))
    # Change altitude on the way: still going there, at the new height.
    assert reposition(gcs, NAN, NAN, FakeNav.ALT + 50.0) == m.MAV_RESULT_ACCEPTED
    going = settled(status, lambda s: s.target_alt_msl_m == FakeNav.ALT + 50.0, "lower")
    assert going.mode == FlightMode.GUIDED and going.target_lat_deg == pytest.approx(lat)
    # Orbit: circle that point at the radius asked for.
    orbit = command_int(gcs, m.MAV_CMD_DO_ORBIT, 150.0, NAN, NAN, NAN,
                        lat=lat, lon=lon, alt=FakeNav.ALT + 60.0)  # fmt: skip
    assert orbit == m.MAV_RESULT_ACCEPTED
    shown(gcs, FlightMode.LOITER)
    assert (
        settled(status, lambda s: s.target_radius_m == 150.0, "orbiting").mode == FlightMode.LOITER
    )
    # Return, then Continue Mission (the Mission mode again; arming is skipped when armed).
    assert set_mode(gcs, FlightMode.RTL) == m.MAV_RESULT_ACCEPTED
    shown(gcs, FlightMode.RTL)
    assert set_mode(gcs, FlightMode.MISSION) == m.MAV_RESULT_ACCEPTED
    shown(gcs, FlightMode.MISSION)
    # Land is never offered for a fixed wing; asked anyway, it lands the mission's landing
    # from its DO_LAND_START, and this plan (the square) has none: back on the runway at
    # home (tests/sitl/test_mavsdk_land.py flies it).
    assert set_mode(gcs, FlightMode.LAND) == m.MAV_RESULT_ACCEPTED
    shown(gcs, FlightMode.LAND)
    # MAVSDK's land() (NAV_LAND, no position) too; a point to land on is refused, said why.
    gcs.command(m.MAV_CMD_NAV_LAND, NAN, NAN, NAN, NAN, FakeNav.LAT, FakeNav.LON, NAN)
    said = [gcs.recv(["STATUSTEXT", "COMMAND_ACK"], 3.0)]  # the refusal's text comes first
    while said[-1].get_type() != "COMMAND_ACK":
        said.append(gcs.recv(["STATUSTEXT", "COMMAND_ACK"], 3.0))
    assert said[-1].result == m.MAV_RESULT_DENIED
    assert any("given point" in x.text for x in said[:-1]), [x.text for x in said[:-1]]
    assert set_mode(gcs, FlightMode.MISSION) == m.MAV_RESULT_ACCEPTED
    gcs.command(m.MAV_CMD_NAV_LAND, *[NAN] * 7)
    assert gcs.ack(m.MAV_CMD_NAV_LAND).result == m.MAV_RESULT_ACCEPTED
    settled(status, lambda s: s.mode == FlightMode.LAND, "landing")
    assert arm(gcs, False, force=True) == m.MAV_RESULT_ACCEPTED


def test_the_old_set_mode_message_works_too(qgc):
    """Vehicle::setFlightMode's fallback when a plug-in has no DO_SET_MODE: SET_MODE."""
    gcs, status, _ = qgc
    for mode in (FlightMode.STABILIZED, FlightMode.GUIDED, FlightMode.RTL, FlightMode.MANUAL):
        flags = m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        gcs.mav.set_mode_send(1, flags, BY_MODE[mode].px4)
        assert gcs.ack(11).result == m.MAV_RESULT_ACCEPTED
        shown(gcs, mode)
        settled(status, lambda s, mode=mode: s.mode == mode, mode.name)


def test_parameters_qgroundcontrols_px4_setup_pages_read_are_there(qgc):
    """PX4AutoPilotPlugin asks each setup page setupComplete() once the parameters are in;
    a parameter it reads and the vehicle lacks ends in a "missing parameters" dialog."""
    gcs, _, _ = qgc
    read_at_connect = {
        "SYS_AUTOSTART",  # AirframeComponent
        "CAL_ACC0_ID", "CAL_GYRO0_ID", "CAL_MAG0_ID", "SYS_HAS_NUM_ASPD",  # SensorsComponent
        "COM_RC_IN_MODE", "RC_MAP_ROLL", "RC_MAP_PITCH", "RC_MAP_YAW", "RC_MAP_THROTTLE",
    }  # fmt: skip
    gcs.mav.param_request_list_send(1, 0)
    first = gcs.recv("PARAM_VALUE", 5.0)
    names = {first.param_id}
    while len(names) < first.param_count:
        names.add(gcs.recv("PARAM_VALUE", 5.0).param_id)
    assert read_at_connect <= names, read_at_connect - names
    # They describe the vehicle (no RC receiver here: the joystick only); a write does not
    # change them. Every name every page reads: tests/protocol/test_qgc_setup_pages.py.
    gcs.mav.param_set_send(1, 1, b"COM_RC_IN_MODE", 4.0, m.MAV_PARAM_TYPE_REAL32)
    assert gcs.recv("PARAM_VALUE", 5.0, param_id="COM_RC_IN_MODE").param_value == 1.0


def test_land_abort_on_the_approach_as_qgroundcontrol_sends_it(vehicle_factory, tmp_path):
    """A stand-in controller on the approach: QGroundControl sees LANDING (so it offers
    Land Abort), and its DO_GO_AROUND is accepted and passed on as a go-around."""
    port = free_udp_port()
    extra = (plugin("approach", FAKE_APPROACH),)
    vehicle = vehicle_factory(client_vehicle(f"udpin://127.0.0.1:{port}", tmp_path, extra))
    gcs = GroundStation(port)
    try:
        gcs.connect()
        status = vehicle.bus.latest_reader("vehicle/status")
        wait_for(status.get, 15, "the commander's first status")
        landing = m.MAV_LANDED_STATE_LANDING
        gcs.recv("EXTENDED_SYS_STATE", 5.0, landed_state=landing)
        gcs.command(m.MAV_CMD_DO_GO_AROUND, 50.0)
        assert gcs.ack(m.MAV_CMD_DO_GO_AROUND).result == m.MAV_RESULT_ACCEPTED
        settled(status, lambda s: s.go_arounds == 1, "the go-around passed on")
    finally:
        gcs.close()


def test_every_mode_qgc44_lists_for_a_fixed_wing_is_flown_and_shown_by_its_name(qgc):
    """QGroundControl 4.4's PX4 plug-in lists Altitude, Position, Acro and Rattitude for a
    fixed wing from its own fixed table (5 lists the vehicle's AVAILABLE_MODES): each,
    picked from the dropdown, is accepted and the heartbeat then shows that very mode."""
    gcs, status, _ = qgc
    for mode in (FlightMode.ALTITUDE, FlightMode.POSITION, FlightMode.ACRO,
                 FlightMode.RATTITUDE, FlightMode.STABILIZED, FlightMode.MANUAL):  # fmt: skip
        assert set_mode(gcs, mode) == m.MAV_RESULT_ACCEPTED, mode
        shown(gcs, mode)
        assert settled(status, lambda s, mode=mode: s.mode == mode, mode.name).mode == mode
    # QGroundControl 5 names them from AVAILABLE_MODES as PX4 reports its fixed-wing modes.
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AVAILABLE_MODES, 0)
    count = len(BY_MODE)
    listed = {}
    for i in range(1, count + 1):
        x = gcs.recv("AVAILABLE_MODES", 3.0, mode_index=i)
        listed[x.mode_name] = x.standard_mode
    assert listed["Altitude"] == m.MAV_STANDARD_MODE_ALTITUDE_HOLD
    assert listed["Position"] == m.MAV_STANDARD_MODE_CRUISE
    assert listed["Acro"] == listed["Rattitude"] == m.MAV_STANDARD_MODE_NON_STANDARD
