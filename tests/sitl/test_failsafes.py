"""Failsafes in lockstep flights: ground-station link lost, GPS lost, fence breached.

A pymavlink ground station (QGroundControl's identity) arms and starts the square plan,
then takes away what the failsafe watches, and checks the mode in the heartbeat and the
STATUSTEXT the operator reads.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator

import pytest

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil

from companion.control.modes import BY_MODE
from companion.messages import FlightMode
from companion.testing.watcher import widen_receive_buffer
from mavlink_dialect import companion as d
from tests.support.vehicle import REPO

PLAN = str(REPO / "qgc_plans" / "square.plan")
pytestmark = pytest.mark.vehicle(plan=PLAN)
WATCHED = ["HEARTBEAT", "STATUSTEXT", "MISSION_CURRENT", "COMMAND_ACK"]


class Station:
    """A ground station that beats only while asked to."""

    def __init__(self, url: str) -> None:
        self.conn = mavutil.mavlink_connection(url, source_system=255)
        widen_receive_buffer(self.conn)
        self.beating = True
        self.texts: list[str] = []
        self.mode = -1
        self.modes: list[int] = []  # every mode the heartbeat has shown, in order
        self.mission_seq = -1
        self.acks: dict[int, int] = {}  # command → the result of its latest COMMAND_ACK
        self._next_beat = 0.0

    def pump(self, seconds: float) -> None:
        """Receive (and beat once a second if beating) for ``seconds`` of wall time."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if self.beating and time.monotonic() >= self._next_beat:
                self.conn.mav.heartbeat_send(d.MAV_TYPE_GCS, d.MAV_AUTOPILOT_INVALID, 0, 0, 0)
                self._next_beat = time.monotonic() + 1.0
            msg = self.conn.recv_match(type=WATCHED, blocking=True, timeout=0.1)
            if msg is None or msg.get_srcSystem() != 1:
                continue
            if msg.get_type() == "STATUSTEXT":
                self.texts.append(msg.text)
            elif msg.get_type() == "MISSION_CURRENT":
                self.mission_seq = msg.seq
            elif msg.get_type() == "COMMAND_ACK":
                self.acks[msg.command] = msg.result
            else:
                self.mode = msg.custom_mode
                if not self.modes or self.modes[-1] != self.mode:
                    self.modes.append(self.mode)

    def until(self, predicate, seconds: float, what: str) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.pump(0.2)
            if predicate():
                return
        raise AssertionError(f"not {what} within {seconds} s; messages: {self.texts}")

    def command(self, command: int, *params: float) -> None:
        values = [*params, 0, 0, 0, 0, 0, 0, 0][:7]
        self.conn.mav.command_long_send(1, 1, command, 0, *values)

    def acked(self, command: int, *params: float) -> int:
        """Send a command and return the result of its COMMAND_ACK."""
        self.acks.pop(command, None)
        self.command(command, *params)
        self.until(lambda: command in self.acks, 10, f"command {command} acknowledged")
        return self.acks[command]

    def in_mode(self, mode: FlightMode) -> bool:
        return self.mode == BY_MODE[mode].px4

    def said(self, words: str) -> bool:
        return any(words in t for t in self.texts)

    def fly_mission(self, stays: bool = True) -> None:
        """Arm and start the mission; with ``stays``, until the heartbeat shows Mission
        (a mission that leaves Mission at once, a take-off aborted in a simulated second,
        can be over before a heartbeat shows it: its ack says it started)."""
        self.until(lambda: self.mode >= 0, 60, "the vehicle heard")
        home = self.conn.recv_match(type="HOME_POSITION", blocking=True, timeout=60)
        assert home is not None, "no home position"
        arm = d.MAV_CMD_COMPONENT_ARM_DISARM
        # As a pilot does: arm once the pre-arm checks pass (the STATUSTEXT says why not).
        self.until(lambda: self.acked(arm, 1) == d.MAV_RESULT_ACCEPTED, 60, "armed")
        started = self.acked(d.MAV_CMD_MISSION_START, 0, 0)
        assert started == d.MAV_RESULT_ACCEPTED, (started, self.texts)
        if stays:
            self.until(lambda: self.in_mode(FlightMode.MISSION), 20, "in Mission")


@pytest.fixture
def station(sim) -> Iterator[Station]:
    """A station on the plug-in's ``sim`` vehicle (the square plan preloaded); the
    vehicle is stopped and checked clean afterwards, whatever the test did."""
    station = Station(sim.pymavlink_url)
    yield station
    station.conn.close()


# The ground station's silence is wall time; a lockstep flight 20-30 times faster than that
# flew the whole square (its last item Return) in the five seconds the failsafe waits. Four
# times real time at most, the losses fall on the first leg, whatever the machine's load.
@pytest.mark.timeout(240)
@pytest.mark.parametrize("sim", [{"speed": 4}], ids=["4x"], indirect=True)
def test_ground_station_lost_returns_home_then_resumes_the_mission_unless_told_to_return(
    station,
):
    station.fly_mission()
    # Airborne, judged by the vehicle (past the take-off item), not by wall time: a
    # busy machine runs the simulation slower.
    station.until(lambda: station.mission_seq >= 1, 120, "past the take-off")
    station.beating = False
    station.until(lambda: station.in_mode(FlightMode.RTL), 30, "returning")
    station.until(lambda: station.said("ground station lost"), 5, "told why")
    station.beating = True
    station.until(lambda: station.in_mode(FlightMode.MISSION), 30, "back in the mission")
    station.until(lambda: station.said("resuming the mission"), 5, "told so")
    # Lost again, and now the operator commands Return (the command gets through while the
    # heartbeats do not, as over a second link): the link's return keeps it.
    station.beating = False
    station.until(lambda: station.in_mode(FlightMode.RTL), 30, "returning again")
    assert station.acked(d.MAV_CMD_NAV_RETURN_TO_LAUNCH) == d.MAV_RESULT_ACCEPTED
    told = sum("Ground station back" in t for t in station.texts)
    station.beating = True
    station.until(
        lambda: sum("Ground station back" in t for t in station.texts) > told, 30, "told it is back"
    )
    station.pump(2.0)
    assert station.in_mode(FlightMode.RTL)
    assert sum("resuming the mission" in t for t in station.texts) == 1
    # Both losses fell in the mission, not after its own Return.
    assert not any("returns to launch" in t for t in station.texts), station.texts


@pytest.mark.timeout(240)
def test_gps_lost_holds_heading_and_loiters_when_it_returns(station):
    # The GPS is switched off as a PX4 user would, with MAV_CMD_INJECT_FAILURE (what
    # MAVSDK's Failure.inject sends), once the aircraft is on its first leg.
    gps, off, ok = d.FAILURE_UNIT_SENSOR_GPS, d.FAILURE_TYPE_OFF, d.FAILURE_TYPE_OK
    station.fly_mission()
    assert station.acked(d.MAV_CMD_INJECT_FAILURE, gps, off) == d.MAV_RESULT_DENIED
    assert station.said("SYS_FAILURE_EN")  # refused until enabled, as PX4
    station.conn.mav.param_set_send(1, 1, b"SYS_FAILURE_EN", 1, d.MAV_PARAM_TYPE_REAL32)
    station.until(lambda: station.mission_seq >= 1, 60, "on the first leg")
    assert station.acked(d.MAV_CMD_INJECT_FAILURE, gps, off) == d.MAV_RESULT_ACCEPTED
    station.until(lambda: station.said("GPS lost"), 60, "told of the GPS loss")
    assert station.in_mode(FlightMode.MISSION)  # the course is held, the mode kept
    assert sum("GPS lost" in t for t in station.texts) == 1  # said once, no flapping
    assert station.acked(d.MAV_CMD_INJECT_FAILURE, gps, ok) == d.MAV_RESULT_ACCEPTED
    loiter = BY_MODE[FlightMode.LOITER].px4
    station.until(lambda: loiter in station.modes, 60, "loitering")
    station.until(lambda: station.said("GPS back"), 30, "told GPS is back")
    station.pump(1.0)
    assert sum("GPS lost" in t for t in station.texts) == 1
    assert sum("GPS back" in t for t in station.texts) == 1


@pytest.mark.timeout(240)
def test_fence_breach_returns_home(station):
    # A 1 km circle round home: the first leg (to 1.8 km east) leaves it.
    lat, lon = -37.9105, 145.1340
    station.fly_mission()
    station.command(d.MAV_CMD_DO_SET_MODE, 1, 4, 3)  # loiter while the fence goes up
    _upload_circle_fence(station, lat, lon, 1000.0)
    station.command(d.MAV_CMD_MISSION_START, 0, 0)
    station.until(lambda: station.said("Fence breached"), 90, "told of the breach")
    station.until(lambda: station.in_mode(FlightMode.RTL), 10, "returning")


def _upload_circle_fence(station: Station, lat: float, lon: float, radius: float) -> None:
    mav, fence = station.conn.mav, d.MAV_MISSION_TYPE_FENCE
    mav.mission_count_send(1, 1, 1, fence)
    req = station.conn.recv_match(
        type=["MISSION_REQUEST_INT", "MISSION_REQUEST"], blocking=True, timeout=10
    )
    assert req is not None
    mav.mission_item_int_send(
        1, 1, 0, d.MAV_FRAME_GLOBAL, d.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION, 0, 1,
        radius, 0, 0, 0, round(lat * 1e7), round(lon * 1e7), 0, fence,
    )  # fmt: skip
    ack = station.conn.recv_match(type="MISSION_ACK", blocking=True, timeout=10)
    assert ack is not None and ack.type == d.MAV_MISSION_ACCEPTED


@pytest.mark.timeout(300)
def test_a_fence_breach_that_holds_takes_back_the_operators_mission_but_not_stabilized(station):
    """QGroundControl's one-click Start Mission outside the fence must not end its Return."""
    lat, lon = -37.9105, 145.1340
    station.fly_mission()
    station.until(lambda: station.mission_seq >= 1, 120, "past the take-off")
    # A fence 5 km north that home is not in: the breach holds however the aircraft flies.
    _upload_circle_fence(station, lat + 0.045, lon, 500.0)
    station.until(lambda: station.in_mode(FlightMode.RTL), 60, "returning")
    mission = BY_MODE[FlightMode.MISSION].px4
    for round_ in range(1, 3):  # Start Mission as QGroundControl's PX4 plug-in sends it
        assert station.acked(d.MAV_CMD_DO_SET_MODE, 1, mission) == d.MAV_RESULT_ACCEPTED
        station.until(lambda n=round_: _count(station, "Fence still breached") == n, 60,
                      "the Return taken back")  # fmt: skip
        station.until(lambda: station.in_mode(FlightMode.RTL), 20, "returning again")
    # Stabilized is taking control: left alone for seconds of vehicle time.
    stabilized = BY_MODE[FlightMode.STABILIZED].px4
    assert station.acked(d.MAV_CMD_DO_SET_MODE, 1, stabilized) == d.MAV_RESULT_ACCEPTED
    station.until(lambda: station.in_mode(FlightMode.STABILIZED), 20, "in Stabilized")
    modes = _modes_for(station, 3.0)
    assert set(modes) == {stabilized}, modes


def _count(station: Station, words: str) -> int:
    return sum(words in t for t in station.texts)


def _modes_for(station: Station, vehicle_s: float) -> list[int]:
    """The heartbeats' modes over the next ``vehicle_s`` of the vehicle's own time
    (GLOBAL_POSITION_INT's time_boot_ms), however fast the simulation runs."""
    modes: list[int] = []
    start = None
    while True:
        msg = station.conn.recv_match(
            type=["HEARTBEAT", "GLOBAL_POSITION_INT"], blocking=True, timeout=30
        )
        assert msg is not None, "the vehicle went quiet"
        if msg.get_srcSystem() != 1:
            continue
        if msg.get_type() == "HEARTBEAT":
            modes.append(msg.custom_mode)
            continue
        start = msg.time_boot_ms if start is None else start
        if msg.time_boot_ms - start >= vehicle_s * 1000 and modes:
            return modes
