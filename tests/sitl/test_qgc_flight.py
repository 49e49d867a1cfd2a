"""QGroundControl's Takeoff, Change altitude and Go to, as its PX4 plug-in sends them
(src/FirmwarePlugin/PX4/PX4FirmwarePlugin.cc: guidedModeTakeoff then arming on the accept,
guidedModeChangeAltitude, guidedModeGotoLocation), fly the simulated aircraft.

Lockstep JSBSim; every wait is on the vehicle's telemetry, never on how fast it ran.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Iterator

import pytest
from pymavlink import mavutil

from companion.control.mission.plan import checked_plan
from companion.control.modes import BY_MODE
from companion.geodesy import LocalFrame
from companion.messages import FlightMode
from mavlink_dialect import companion as d
from tests.sim.sim_run import sim_running
from tests.support.vehicle import REPO

NAN = math.nan
WAIT_S = 240.0  # wall seconds for any one stage: generous, for a loaded machine


class Qgc:
    """Just enough of QGroundControl: a heartbeat, commands, and what the vehicle says."""

    def __init__(self, port: int) -> None:
        self.conn = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=255,
                                               source_component=190)  # fmt: skip
        self.mode = -1
        self.position = None
        self.acks: dict[int, int] = {}
        self.mission_current = None

    def pump_until(self, predicate, what: str) -> None:
        deadline = time.monotonic() + WAIT_S
        while time.monotonic() < deadline:
            self.conn.mav.heartbeat_send(d.MAV_TYPE_GCS, d.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            for _ in range(50):
                msg = self.conn.recv_match(blocking=True, timeout=0.02)
                if msg is not None and msg.get_srcSystem() == 1:
                    self._take(msg)
            if predicate():
                return
        raise AssertionError(f"never {what}")

    def _take(self, msg) -> None:
        kind = msg.get_type()
        if kind == "HEARTBEAT":
            self.mode = msg.custom_mode
        elif kind == "GLOBAL_POSITION_INT":
            self.position = msg
        elif kind == "COMMAND_ACK":
            self.acks[msg.command] = msg.result
        elif kind == "MISSION_CURRENT":
            self.mission_current = msg

    def command(self, command: int, *params: float) -> int:
        self.acks.pop(command, None)
        self.conn.mav.command_long_send(1, 1, command, 0, *params)
        self.pump_until(lambda: command in self.acks, f"an answer to {command}")
        return self.acks[command]

    def command_int(self, command: int, *params: float, lat: float, lon: float, alt: float):
        self.acks.pop(command, None)
        self.conn.mav.command_int_send(1, 1, d.MAV_FRAME_GLOBAL, command, 0, 0, *params,
                                       round(lat * 1e7), round(lon * 1e7), alt)  # fmt: skip
        self.pump_until(lambda: command in self.acks, f"an answer to {command}")
        return self.acks[command]

    def in_mode(self, mode: FlightMode) -> bool:
        return self.mode == BY_MODE[mode].px4


@contextlib.contextmanager
def _qgc_and_sim(tmp_path) -> Iterator[Qgc]:
    """The c172p on the runway in ``companion sim`` and QGroundControl's link to it."""
    with sim_running(tmp_path, "--aircraft", "c172p") as (port, _proc, _truth):
        qgc = Qgc(port)
        try:
            yield qgc
        finally:
            qgc.conn.close()


@pytest.mark.timeout(900)
def test_qgroundcontrol_takeoff_change_altitude_and_go_to_fly(tmp_path):
    with _qgc_and_sim(tmp_path) as qgc:
        home = qgc.conn.recv_match(type="HOME_POSITION", blocking=True, timeout=60)
        assert home is not None, "no home position"
        home_amsl = home.altitude / 1000.0
        frame = LocalFrame(home.latitude / 1e7, home.longitude / 1e7)
        arm = d.MAV_CMD_COMPONENT_ARM_DISARM
        qgc.pump_until(lambda: qgc.position is not None, "a position")
        # Takeoff to 60 m (the slider), then arm once the command is accepted; the pre-arm
        # checks may still wait for the GPS: QGroundControl's user presses again.
        takeoff = (-1, 0, 0, NAN, NAN, NAN, home_amsl + 60.0)
        assert qgc.command(d.MAV_CMD_NAV_TAKEOFF, *takeoff) == d.MAV_RESULT_ACCEPTED
        qgc.pump_until(lambda: qgc.command(arm, 1, 0, 0, 0, 0, 0, 0) == 0, "armed")
        qgc.pump_until(lambda: qgc.position.relative_alt > 50_000, "at the take-off height")
        assert qgc.in_mode(FlightMode.TAKEOFF)
        # Change altitude (pause first, then the new height): circle here 40 m higher.
        assert qgc.command(d.MAV_CMD_DO_REPOSITION, -1, 1, 0, NAN, NAN, NAN, NAN) == 0
        assert qgc.command(d.MAV_CMD_DO_REPOSITION, -1, 1, 0, NAN, NAN, NAN, home_amsl + 100) == 0
        qgc.pump_until(lambda: qgc.in_mode(FlightMode.LOITER), "in Hold (our Loiter)")
        qgc.pump_until(lambda: qgc.position.relative_alt > 90_000, "40 m higher")
        # Go to a point 1.5 km east, at the present height (COMMAND_INT, frame GLOBAL).
        lat, lon = frame.latlon(0.0, 1500.0)
        go = qgc.command_int(d.MAV_CMD_DO_REPOSITION, -1, 1, 0, NAN, lat=lat, lon=lon,
                             alt=qgc.position.alt / 1000.0)  # fmt: skip
        assert go == d.MAV_RESULT_ACCEPTED
        qgc.pump_until(lambda: qgc.in_mode(FlightMode.GUIDED), "in Guided")

        def near() -> bool:
            n, e = frame.ne(qgc.position.lat / 1e7, qgc.position.lon / 1e7)
            return math.hypot(n, e - 1500.0) < 300.0

        qgc.pump_until(near, "at the go-to point")
        assert qgc.in_mode(FlightMode.GUIDED)  # it circles there, still Guided
        assert abs(qgc.position.relative_alt / 1000.0 - 100.0) < 20.0


@pytest.mark.timeout(900)
def test_qgc_custom_takeoff_and_loiter_actions_fly_and_hold_the_height(tmp_path):
    """The shipped custom actions (qgc/companion-actions.*.json) send their command with
    every parameter 0 (COMMAND_LONG). "Takeoff" (NAV_TAKEOFF), then the toolbar's Arm:
    QGroundControl 4.4.5 greys out its own Takeoff for a fixed wing, and this takes off to
    the return height (RTL_ALT_M, 100 m). "Loiter" (NAV_LOITER_UNLIM), read as 0 m above
    sea level, had the aircraft descending from 99 m to 40 m above the ground in 20 s; now
    it circles here at the height it had."""
    with _qgc_and_sim(tmp_path) as qgc:
        home = qgc.conn.recv_match(type="HOME_POSITION", blocking=True, timeout=60)
        assert home is not None, "no home position"
        qgc.pump_until(lambda: qgc.position is not None, "a position")
        assert qgc.command(d.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 0) == d.MAV_RESULT_ACCEPTED
        qgc.pump_until(lambda: qgc.in_mode(FlightMode.TAKEOFF), "in Takeoff")
        arm = d.MAV_CMD_COMPONENT_ARM_DISARM
        qgc.pump_until(lambda: qgc.command(arm, 1, 0, 0, 0, 0, 0, 0) == 0, "armed")
        qgc.pump_until(lambda: qgc.position.relative_alt > 95_000, "at the return height")
        sent_at = qgc.position.relative_alt / 1000.0
        assert qgc.command(d.MAV_CMD_NAV_LOITER_UNLIM, 0, 0, 0, 0, 0, 0, 0) == 0
        qgc.pump_until(lambda: qgc.in_mode(FlightMode.LOITER), "in Hold (our Loiter)")
        start_ms, lowest = qgc.position.time_boot_ms, sent_at

        def watched() -> bool:
            nonlocal lowest
            lowest = min(lowest, qgc.position.relative_alt / 1000.0)
            return qgc.position.time_boot_ms - start_ms > 40_000

        qgc.pump_until(watched, "40 s in Hold")
        assert qgc.in_mode(FlightMode.LOITER)
        assert lowest > sent_at - 10.0, (sent_at, lowest)


def _upload(qgc: Qgc, plan: str) -> None:
    """The Plan view's Upload: MISSION_COUNT, then each item as the vehicle asks for it."""
    items = checked_plan(REPO / "qgc_plans" / plan)[d.MAV_MISSION_TYPE_MISSION]
    qgc.conn.mav.mission_count_send(1, 1, len(items), d.MAV_MISSION_TYPE_MISSION)
    for _ in items:
        req = qgc.conn.recv_match(type="MISSION_REQUEST_INT", blocking=True, timeout=10)
        assert req is not None, "the vehicle asked for no item"
        it = items[req.seq]
        qgc.conn.mav.mission_item_int_send(
            1, 1, it.seq, it.frame, it.command, 0, it.autocontinue, it.param1, it.param2,
            it.param3, it.param4, it.x, it.y, it.z, d.MAV_MISSION_TYPE_MISSION,
        )  # fmt: skip
    ack = qgc.conn.recv_match(type="MISSION_ACK", blocking=True, timeout=10)
    assert ack is not None and ack.type == d.MAV_MISSION_ACCEPTED


@pytest.mark.timeout(900)
def test_pause_keeps_the_mission_item_and_continue_mission_resumes_it(tmp_path):
    """MISSION_CURRENT had fallen to item 0 when the aircraft left Mission, so
    QGroundControl showed the plan as not started; now it keeps the item, PAUSED."""
    with _qgc_and_sim(tmp_path) as qgc:
        assert qgc.conn.recv_match(type="HEARTBEAT", blocking=True, timeout=60) is not None
        _upload(qgc, "square.plan")
        mission = BY_MODE[FlightMode.MISSION].px4
        flag = d.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        # Repeated: a mode asked before the link has seen the commander is UNSUPPORTED.
        set_mission = (d.MAV_CMD_DO_SET_MODE, flag, mission, 0, 0, 0, 0, 0)
        qgc.pump_until(lambda: qgc.command(*set_mission) == 0, "in Mission")
        arm = d.MAV_CMD_COMPONENT_ARM_DISARM
        qgc.pump_until(lambda: qgc.command(arm, 1, 0, 0, 0, 0, 0, 0) == 0, "armed")
        qgc.pump_until(lambda: qgc.mission_current is not None and qgc.mission_current.seq >= 2,
                       "flying to the second waypoint")  # fmt: skip
        # Pause (PX4FirmwarePlugin::pauseVehicle): Hold, the plan still at its item.
        assert qgc.command(d.MAV_CMD_DO_REPOSITION, -1, 1, 0, NAN, NAN, NAN, NAN) == 0
        qgc.pump_until(lambda: qgc.in_mode(FlightMode.LOITER), "in Hold")
        paused = d.MISSION_STATE_PAUSED
        qgc.pump_until(lambda: qgc.mission_current.mission_state == paused, "said PAUSED")
        at = qgc.mission_current.seq
        assert at >= 2
        paused_at = qgc.position.time_boot_ms

        def ten_seconds_paused() -> bool:
            current = qgc.mission_current
            assert (current.seq, current.mission_state) == (at, paused)
            return qgc.position.time_boot_ms - paused_at > 10_000

        qgc.pump_until(ten_seconds_paused, "10 s paused")
        # Continue Mission: the same item again, flown on.
        assert qgc.command(d.MAV_CMD_DO_SET_MODE, flag, mission, 0, 0, 0, 0, 0) == 0
        qgc.pump_until(lambda: qgc.mission_current.mission_state == d.MISSION_STATE_ACTIVE,
                       "the mission active again")  # fmt: skip
        assert qgc.mission_current.seq >= at
