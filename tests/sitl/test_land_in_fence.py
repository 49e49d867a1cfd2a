"""QGroundControl 4.4.5's Land with the square plan and its fence (issue 42's click-through).

The Plan view's upload (mission, fence, rally), Start Mission, Return, then the shipped
custom action Land (COMMAND_LONG MAV_CMD_NAV_LAND, every parameter 0). The plan has no
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

import pytest

from companion.control.flight.landing_pattern import patterns
from companion.control.mission.fence import Fence
from companion.control.mission.plan import checked_plan
from companion.control.modes import BY_MODE
from companion.geodesy import LocalFrame, wrap_pi
from companion.messages import FlightMode
from companion.navigation.estimate_csv import read_estimate
from ground.campaign.landing_score import score_landing
from mavlink_dialect import companion as d
from tests.protocol.mav_client import GroundStation
from tests.support.vehicle import REPO

log = logging.getLogger(__name__)
PLAN = REPO / "qgc_plans" / "square.plan"
pytestmark = pytest.mark.vehicle(airframe="c172p", duration=1500)
WALL_S = 1500.0  # a hang guard only: the flight is judged by the vehicle's telemetry
SAID = re.compile(r"Land: course (\d+), (\d+) m final, loiter (right|left)")


def _accepted(qgc: GroundStation, command: int, *params: float) -> None:
    qgc.command(command, *params)
    assert qgc.ack(command).result == d.MAV_RESULT_ACCEPTED


def _until_disarmed(qgc: GroundStation) -> tuple[list[FlightMode], list[str]]:
    """The modes the heartbeat showed and the texts said, until the vehicle disarmed; the
    ground station beats once a second meanwhile, as QGroundControl does."""
    modes: list[FlightMode] = []
    texts: list[str] = []
    by_px4 = {m.px4: mode for mode, m in BY_MODE.items()}
    end, beat = time.monotonic() + WALL_S, 0.0
    while time.monotonic() < end:
        if time.monotonic() > beat:
            qgc.heartbeat()
            beat = time.monotonic() + 1.0
        msg = qgc.conn.recv_match(type=["HEARTBEAT", "STATUSTEXT"], blocking=True, timeout=1)
        if msg is None or msg.get_srcSystem() != 1:
            continue
        if msg.get_type() == "STATUSTEXT":
            texts.append(msg.text)
            continue
        if msg.get_srcComponent() != 1:
            continue
        mode = by_px4.get(msg.custom_mode)
        if mode is not None and (not modes or modes[-1] != mode):
            modes.append(mode)
        if not msg.base_mode & d.MAV_MODE_FLAG_SAFETY_ARMED:
            return modes, texts
    raise AssertionError(f"never disarmed; modes {modes}, texts {texts[-10:]}")


@pytest.mark.timeout(1800)
def test_qgc_land_with_the_square_plans_fence_lands_inside_it(sim):
    sim.wait_ready()
    counts = sim.upload_plan(PLAN)  # as the Plan view's Upload: each type it has
    assert counts[d.MAV_MISSION_TYPE_FENCE] == 4
    qgc = GroundStation(sim.ports.pymavlink)
    try:
        qgc.connect()
        sim.arm_and_start()
        sim.run_until_item(2)  # on the square, past its first waypoint
        flag = d.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        _accepted(qgc, d.MAV_CMD_DO_SET_MODE, flag, BY_MODE[FlightMode.RTL].px4)
        _accepted(qgc, d.MAV_CMD_NAV_LAND, 0, 0, 0, 0, 0, 0, 0)  # the custom action
        modes, texts = _until_disarmed(qgc)
    finally:
        qgc.close()
    assert not any("Fence breached" in t for t in texts), texts
    assert modes[-1] == FlightMode.LAND, modes  # never Return again once landing
    said = next((m for t in texts if (m := SAID.search(t))), None)
    assert said is not None, texts
    truth = read_estimate(sim.truth_path)
    fence = Fence.from_items(checked_plan(PLAN)[d.MAV_MISSION_TYPE_FENCE])
    track = zip(truth["lat"], truth["lon"], strict=True)
    outside = [k for k, (lat, lon) in enumerate(track) if fence.breach(lat, lon)]
    assert not outside, f"{len(outside)} truth samples outside the fence"
    score = _score(truth, int(said[1]), float(said[2]), said[3] == "right")
    log.info("landing on the pattern it said (%s): %s", said[0], score)
    assert score.landed and score.stopped and score.on_runway, score
    assert abs(score.along_m) < 30.0 and abs(score.across_m) < 5.0, score
    assert score.sink_m_s < 1.5, score


def _score(truth, course_deg: int, approach_m: float, clockwise: bool):
    """The landing judged on the pattern the vehicle said it flies: the runway is the take-off
    roll's (from where the aircraft stood, along the way it rolled)."""
    frame = LocalFrame(truth["lat"][0], truth["lon"][0])
    speed = [math.hypot(n, e) for n, e in zip(truth["vn"], truth["ve"], strict=True)]
    moving = next(k for k, v in enumerate(speed) if v > 5.0)
    heading = math.atan2(truth["ve"][moving], truth["vn"][moving])
    course = math.radians(course_deg)
    pattern = min(
        (p for p in patterns((0.0, 0.0), heading, approach_m) if p.clockwise == clockwise),
        key=lambda p: abs(wrap_pi(p.heading - course)),
    )
    return score_landing(truth, frame.latlon(*pattern.centre), frame.latlon(*pattern.touchdown),
                         pattern.radius, clockwise)  # fmt: skip
