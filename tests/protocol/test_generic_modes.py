"""The generic profile (``autopilot = "generic"``, for MAVProxy) numbers modes as ArduPlane:
every ArduPlane mode number pymavlink knows is flown as its counterpart or refused with a
reason, and the HEARTBEAT, CURRENT_MODE and AVAILABLE_MODES then carry ArduPlane's number,
which pymavlink (hence MAVProxy's prompt) names."""

from __future__ import annotations

import time

import pytest
from pymavlink import mavutil

from companion.control.mission.mission_files import MissionStore
from companion.control.mission.plan import checked_plan
from companion.control.modes import BY_MODE, GENERIC_RATTITUDE, MODES
from companion.messages import FlightMode
from mavlink_dialect import companion as m
from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.protocol.test_qgc_custom_actions import EXPECTED, QGC44, load_qgc44
from tests.support.configs import client_vehicle
from tests.support.vehicle import REPO, wait_for

F = FlightMode
# ArduPlane's mode (pymavlink's mode_mapping_apm) -> the vehicle mode that flies as it does.
FLOWN = {
    "MANUAL": F.MANUAL,
    "CIRCLE": F.LOITER,  # circles where it is
    "STABILIZE": F.STABILIZED,  # wings levelled when the sticks are released
    "ACRO": F.ACRO,
    "FBWA": F.STABILIZED,
    "FBWB": F.ALTITUDE,
    "CRUISE": F.POSITION,  # heading (track) and height held
    "AUTO": F.MISSION,
    "RTL": F.RTL,
    "LOITER": F.LOITER,
    "TAKEOFF": F.TAKEOFF,
    "GUIDED": F.GUIDED,
    "AUTOLAND": F.LAND,
}
ARDUPLANE = {name: number for number, name in mavutil.mode_mapping_apm.items()}


def ack_and_texts(gcs: GroundStation) -> tuple[int, list[str]]:
    """DO_SET_MODE's result and the texts said with it (the link's refusal comes first)."""
    texts: list[str] = []
    while True:
        msg = gcs.recv(["COMMAND_ACK", "STATUSTEXT"], 15.0)
        if msg.get_type() == "STATUSTEXT":
            texts.append(msg.text)
        elif msg.command == m.MAV_CMD_DO_SET_MODE:
            if msg.result == m.MAV_RESULT_DENIED:  # the commander's reason follows its ack
                texts += [t.text for t in drain(gcs, "STATUSTEXT", 1.0)]
            return msg.result, texts


def drain(gcs: GroundStation, type_: str, seconds: float) -> list:
    end, out = time.monotonic() + seconds, []
    while time.monotonic() < end:
        if (msg := gcs.conn.recv_match(type=type_, blocking=True, timeout=0.1)) is not None:
            out.append(msg)
    return out


@pytest.fixture
def generic(vehicle_factory, tmp_path):
    """A generic-profile vehicle with a mission and home, and a ground station on it."""
    state = tmp_path / "state"
    store = MissionStore(state / "missions")
    for kind, items in checked_plan(REPO / "qgc_plans/square.plan").items():
        store.replace(kind, items)
    port = free_udp_port()
    vehicle = vehicle_factory(
        client_vehicle(f"udpin://127.0.0.1:{port}", state, autopilot="generic")
    )
    gcs = GroundStation(port)
    gcs.connect()
    status = vehicle.bus.latest_reader("vehicle/status")
    wait_for(lambda: status.get() is not None and status.get().home_valid, 60, "home")
    yield gcs, status
    gcs.close()


def test_every_arduplane_mode_is_flown_or_refused_and_reported_by_its_number(generic):
    gcs, status = generic
    for number, name in sorted(mavutil.mode_mapping_apm.items()):
        gcs.command(m.MAV_CMD_DO_SET_MODE, m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, number)
        result, texts = ack_and_texts(gcs)
        if name not in FLOWN:
            assert result == m.MAV_RESULT_DENIED, name
            assert any(t.startswith("Set mode:") for t in texts), (name, texts)
            continue
        assert result == m.MAV_RESULT_ACCEPTED, name
        mode = FLOWN[name]
        wait_for(lambda mode=mode: status.get().mode == mode, 15, f"{name}: {mode.name}")
        # The mode's own ArduPlane number (CIRCLE is reported as LOITER, FBWA as STABILIZE's
        # counterpart FBWA): what pymavlink and MAVProxy name.
        shown = BY_MODE[mode].arduplane
        beat = gcs.recv("HEARTBEAT", 5.0, custom_mode=shown)
        assert beat.autopilot == m.MAV_AUTOPILOT_GENERIC
        assert mavutil.mode_string_v10(beat) == mavutil.mode_mapping_apm[shown]
        assert gcs.recv("CURRENT_MODE", 5.0, custom_mode=shown).intended_custom_mode == shown


def test_arduplane_names_in_the_heartbeat_and_available_modes(generic):
    gcs, _ = generic
    beat = gcs.recv("HEARTBEAT", 5.0, custom_mode=ARDUPLANE["LOITER"])  # the initial mode
    assert mavutil.mode_string_v10(beat) == "LOITER"
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AVAILABLE_MODES, 0)
    assert gcs.ack(m.MAV_CMD_REQUEST_MESSAGE).result == m.MAV_RESULT_ACCEPTED
    listed = [gcs.recv("AVAILABLE_MODES", 3.0, mode_index=i) for i in range(1, len(MODES) + 1)]
    assert [x.custom_mode for x in listed] == [info.generic for info in MODES]
    assert len({x.custom_mode for x in listed}) == len(MODES)
    # Rattitude, which ArduPlane lacks, has a number outside ArduPlane's table.
    assert GENERIC_RATTITUDE not in mavutil.mode_mapping_apm
    assert BY_MODE[F.RATTITUDE].generic == GENERIC_RATTITUDE


def test_px4_main_and_sub_modes_still_read_in_the_generic_profile(generic):
    gcs, status = generic
    gcs.command(m.MAV_CMD_DO_SET_MODE, m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 4, 5)  # AUTO.RTL
    assert gcs.ack(m.MAV_CMD_DO_SET_MODE).result == m.MAV_RESULT_ACCEPTED
    wait_for(lambda: status.get().mode == F.RTL, 15, "Return")
    gcs.command(m.MAV_CMD_DO_SET_MODE, m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, BY_MODE[F.LOITER].px4)
    assert gcs.ack(m.MAV_CMD_DO_SET_MODE).result == m.MAV_RESULT_ACCEPTED
    wait_for(lambda: status.get().mode == F.LOITER, 15, "Loiter")
    assert gcs.recv("HEARTBEAT", 5.0, custom_mode=ARDUPLANE["LOITER"])


def test_the_shipped_qgroundcontrol_actions_do_what_their_labels_say(generic):
    # Under generic too, where QGroundControl offers no guided action and these buttons are
    # the way to change modes: Stabilized is PX4's whole custom_mode, read alike by both.
    gcs, status = generic
    for label, command, compid, params in load_qgc44(QGC44):
        gcs.command(command, *params, target=(1, compid))
        assert gcs.ack(command).result == m.MAV_RESULT_ACCEPTED, label
        mode = EXPECTED[label]
        wait_for(lambda mode=mode: status.get().mode == mode, 15, label)
        assert gcs.recv("HEARTBEAT", 5.0, custom_mode=BY_MODE[mode].arduplane)
