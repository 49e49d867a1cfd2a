"""QGroundControl 4.4.5's Land with the square plan and its fence (issue 42's click-through).

The Plan view's upload (mission, fence, rally), Start Mission, Return (to the plan's rally
point, nearer than home from the square's far side), then the shipped custom action Land
(COMMAND_LONG MAV_CMD_NAV_LAND, every parameter 0). The plan has no
landing, so Land builds its pattern onto the runway of the take-off; the default one's
loiter (800 m behind the touchdown point) lay across the fence's west edge, 700 m west of
home, and the fence failsafe turned the landing into Return. Now the pattern keeps inside
the fence: the aircraft lands without a breach, stops on the runway and disarms itself.
Lockstep JSBSim; the track is judged by the simulator's truth.
"""

from __future__ import annotations

import logging
import math
import re
import time
from collections.abc import Callable

import pytest

from companion.control.flight.landing_pattern import patterns
from companion.control.mission.fence import Fence
from companion.control.mission.plan import checked_plan
from companion.control.modes import BY_MODE
from companion.geodesy import LocalFrame, wrap_pi
from companion.messages import FlightMode
from ground.campaign.landing_score import LandingScore, read_truth, score_landing
from mavlink_dialect import companion as d
from tests.protocol.mav_client import GroundStation
from tests.support.vehicle import REPO, wait_for

log = logging.getLogger(__name__)
PLAN = REPO / "qgc_plans" / "square.plan"
pytestmark = pytest.mark.vehicle(airframe="c172p")
WALL_S = 1500.0  # a hang guard only: the flight is judged by the vehicle's telemetry
HOME = LocalFrame(-37.9105, 145.134)  # the plan's home, where the simulation starts
NEAR_M = 500.0  # Land from Return once this near where it returns to
_RALLY_ITEM = checked_plan(PLAN)[d.MAV_MISSION_TYPE_RALLY][0]
RALLY = HOME.ne(_RALLY_ITEM.x / 1e7, _RALLY_ITEM.y / 1e7)
CLIMB_OUT_CHECK_M = 200.0  # the roll and the wings-level climb-out follow the runway line
SAID = re.compile(r"Land: course (\d+), (\d+) m final, loiter (right|left)")


class Heard:
    """What QGroundControl's Fly view shows: the modes in turn, the messages, the position.
    ``pump`` beats once a second meanwhile, as QGroundControl does."""

    def __init__(self, qgc: GroundStation) -> None:
        self.qgc = qgc
        self.modes: list[FlightMode] = []
        self.texts: list[str] = []
        self.armed = True
        self.rally_m = math.inf  # from the plan's rally point, where Return goes
        self._by_px4 = {m.px4: mode for mode, m in BY_MODE.items()}

    def pump(self, done: Callable[[], bool], what: str) -> None:
        end, beat = time.monotonic() + WALL_S, 0.0
        kinds = ["HEARTBEAT", "STATUSTEXT", "GLOBAL_POSITION_INT"]
        while time.monotonic() < end and not done():
            if time.monotonic() > beat:
                self.qgc.heartbeat()
                beat = time.monotonic() + 1.0
            msg = self.qgc.conn.recv_match(type=kinds, blocking=True, timeout=1)
            if msg is not None and msg.get_srcSystem() == 1 and msg.get_srcComponent() == 1:
                self._take(msg)
        assert done(), f"never {what}; modes {self.modes}, texts {self.texts[-10:]}"

    def accepted(self, command: int, *params: float, timeout_s: float = 15.0) -> None:
        """Send a command and see it accepted, taking in what comes meanwhile: the vehicle
        may say where Return goes before the ack reaches the station."""
        self.qgc.command(command, *params)
        end = time.monotonic() + timeout_s
        kinds = ["COMMAND_ACK", "HEARTBEAT", "STATUSTEXT", "GLOBAL_POSITION_INT"]
        while time.monotonic() < end:
            msg = self.qgc.conn.recv_match(type=kinds, blocking=True, timeout=0.2)
            if msg is None or msg.get_srcSystem() != 1 or msg.get_srcComponent() != 1:
                continue
            if msg.get_type() != "COMMAND_ACK":
                self._take(msg)
            elif msg.command == command:
                assert msg.result == d.MAV_RESULT_ACCEPTED, (command, msg.result, self.texts)
                return
        raise AssertionError(f"no COMMAND_ACK for {command} within {timeout_s} s")

    def _take(self, msg) -> None:
        kind = msg.get_type()
        if kind == "STATUSTEXT":
            self.texts.append(msg.text)
        elif kind == "GLOBAL_POSITION_INT":
            north, east = HOME.ne(msg.lat / 1e7, msg.lon / 1e7)
            self.rally_m = math.hypot(north - RALLY[0], east - RALLY[1])
        else:
            mode = self._by_px4.get(msg.custom_mode)
            if mode is not None and (not self.modes or self.modes[-1] != mode):
                self.modes.append(mode)
            self.armed = bool(msg.base_mode & d.MAV_MODE_FLAG_SAFETY_ARMED)


@pytest.mark.timeout(1800)
def test_qgc_land_with_the_square_plans_fence_lands_inside_it(sim):
    sim.wait_ready()
    counts = sim.upload_plan(PLAN)  # as the Plan view's Upload: each type it has
    assert counts[d.MAV_MISSION_TYPE_FENCE] == 4
    sim.arm_and_start()
    sim.run_until_item(2)  # on the square, past its first waypoint
    # QGroundControl joins now: from here on it beats once a second (its loss would be
    # the ground-station failsafe's Return, not the fence's).
    qgc = GroundStation(sim.ports.pymavlink)
    heard = Heard(qgc)
    try:
        qgc.connect()
        flag = d.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        heard.accepted(d.MAV_CMD_DO_SET_MODE, flag, BY_MODE[FlightMode.RTL].px4)  # Return
        heard.pump(lambda: heard.rally_m < NEAR_M, "near the rally point")
        heard.accepted(d.MAV_CMD_NAV_LAND, 0, 0, 0, 0, 0, 0, 0)  # the custom action Land
        heard.pump(lambda: not heard.armed, "disarmed")
    finally:
        qgc.close()
    # The simulator writes its truth file as it goes: read it once it holds the aircraft
    # standing after the disarm (a busy machine flushes it late).
    settled = sim.run_until_time(sim.run_until_time(0.0) + 5.0)
    wait_for(lambda: sim.truth()["t"][-1] >= settled, 120, "the truth file past the disarm")
    modes, texts = heard.modes, heard.texts
    assert not any("Fence breached" in t for t in texts), texts
    assert any(t.startswith("Return: to rally point 1") for t in texts), texts
    landing = modes[modes.index(FlightMode.LAND) :] if FlightMode.LAND in modes else []
    assert landing == [FlightMode.LAND], modes  # Land to the end: no Return after it
    said = next((m for t in texts if (m := SAID.search(t))), None)
    assert said is not None, texts
    truth = read_truth(sim.truth_path)
    fence = Fence.from_items(checked_plan(PLAN)[d.MAV_MISSION_TYPE_FENCE])
    track = zip(truth["lat"], truth["lon"], strict=True)
    outside = [k for k, (lat, lon) in enumerate(track) if fence.breach(lat, lon)]
    assert not outside, f"{len(outside)} truth samples outside the fence"
    score = _score(truth, int(said[1]), float(said[2]), said[3] == "right")
    log.info("landing on the pattern it said (%s): %s", said[0], score)
    assert score.landed and score.stopped and score.on_runway, score
    # The take-off was eastwards and the default loiter west of home, outside: it landed
    # the other way along the runway.
    assert math.cos(math.radians(int(said[1])) - _runway(truth)[1]) < -0.9, said[0]
    assert abs(score.along_m) < 30.0 and abs(score.across_m) < 5.0, score
    assert score.sink_m_s < 1.5, score


def _runway(truth) -> tuple[LocalFrame, float]:
    """The take-off's runway: from where the aircraft stood along the line it rolled and
    climbed out on (the line the vehicle believed; its heading at rest was 2 degrees off)."""
    frame = LocalFrame(truth["lat"][0], truth["lon"][0])
    track = [frame.ne(lat, lon) for lat, lon in zip(truth["lat"], truth["lon"], strict=True)]
    rolled = next(p for p in track if math.hypot(*p) > CLIMB_OUT_CHECK_M)
    return frame, math.atan2(rolled[1], rolled[0])


def _score(truth, course_deg: int, approach_m: float, clockwise: bool) -> LandingScore:
    """The landing judged on the pattern the vehicle said it flies."""
    frame, heading = _runway(truth)
    course = math.radians(course_deg)
    pattern = min(
        (p for p in patterns((0.0, 0.0), heading, approach_m) if p.clockwise == clockwise),
        key=lambda p: abs(wrap_pi(p.heading - course)),
    )
    return score_landing(truth, frame.latlon(*pattern.centre), frame.latlon(*pattern.touchdown),
                         pattern.radius, clockwise)  # fmt: skip
