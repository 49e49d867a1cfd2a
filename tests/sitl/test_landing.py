"""A whole-vehicle landing in lockstep JSBSim, flown as a ground station would fly it.

The benchmark's plan (take off east, a loop, QGroundControl's landing pattern back onto
the runway) is uploaded item by item over MAVLink exactly as QGroundControl uploads the
pattern (DO_LAND_START, camera stops, LOITER_TO_ALT, NAV_LAND); the aircraft is armed and
the mission started from the ground station at the simulated second the simulator holds
for them (``--hold-at``), so in exact lockstep the flight is the same every run, whatever
the machine's load: the same gusts on the same approach. In a 5 m/s crosswind with light
turbulence it lands on the target (within 15 m along and 2 m across), touches down at no
more than 1.5 m/s with the wings within 10° of level and no bounce over 1 m, stops on the
runway, and disarms itself; the ground station sees the landed state go TAKEOFF, IN_AIR,
LANDING, ON_GROUND; the flare flies on the simulated TFmini's height.
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest
from pyulog import ULog

from companion.control.mission.items import MissionItem
from companion.control.mission.plan import checked_plan
from companion.testing.processes import stop_tree
from ground.campaign.landing_score import landing_score_for_plan, read_truth
from mavlink_dialect import companion as d
from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.sim.sim_run import SimRun, finish, start_sim
from tests.support.vehicle import REPO

PLAN = REPO / "benchmarks" / "plans" / "land_east.plan"
# A hang guard only: the flight is judged by the simulator's truth. Alone the 250 s flight
# takes about 2 min; a CI run beside several other simulations took over 600 s to the stop.
WALL_LIMIT_S = 1500.0
HOLD_AT_S = 10.0  # the simulated second the flight starts at (the campaigns' start-at)
HOLDING = "holding the simulation at"


def _upload(gcs: GroundStation, items: list[MissionItem]) -> None:
    gcs.mav.mission_count_send(1, 1, len(items), d.MAV_MISSION_TYPE_MISSION)
    for _ in items:
        req = gcs.recv(["MISSION_REQUEST_INT", "MISSION_REQUEST"], 10)
        it = items[req.seq]
        gcs.mav.mission_item_int_send(
            1, 1, it.seq, it.frame, it.command, 0, it.autocontinue, it.param1, it.param2,
            it.param3, it.param4, it.x, it.y, it.z, d.MAV_MISSION_TYPE_MISSION,
        )  # fmt: skip
    assert gcs.recv("MISSION_ACK", 10).type == d.MAV_MISSION_ACCEPTED


def _command_until_accepted(gcs: GroundStation, command: int, *params: float) -> None:
    """Send until accepted, as a person clicks again; on giving up, say what the vehicle
    answered and why (its ``PreArm:`` STATUSTEXTs)."""
    end, answers, said = time.monotonic() + 60.0, [], set()
    while time.monotonic() < end:  # arming waits for the first GPS fix
        gcs.heartbeat()
        gcs.command(command, *params)
        until = time.monotonic() + 10.0
        while time.monotonic() < until:
            msg = gcs.conn.recv_match(
                type=["COMMAND_ACK", "STATUSTEXT"], blocking=True, timeout=0.2
            )
            if msg is None or msg.get_srcSystem() != 1:
                continue
            if msg.get_type() == "STATUSTEXT":
                said.add(msg.text)
            elif msg.command == command:
                if msg.result == d.MAV_RESULT_ACCEPTED:
                    return
                answers.append(msg.result)
                break
        time.sleep(0.5)
    raise AssertionError(f"command {command} never accepted: answers {answers}, said {said}")


def _wait_for_the_hold(proc: SimRun) -> None:
    """Wait until the simulator holds for the arming: a command sent before that would
    arm the vehicle at whichever frame it happened to arrive in."""
    end = time.monotonic() + WALL_LIMIT_S
    while HOLDING not in proc.output():
        assert proc.poll() is None and time.monotonic() < end, proc.output()[-3000:]
        time.sleep(0.2)


def _fly(gcs: GroundStation) -> tuple[bool, bool, list[int]]:
    """(mission completed, disarmed after having been armed, the landed states in turn) as
    the ground station saw them."""
    completed = armed = disarmed = False
    states: list[int] = []
    end, beat = time.monotonic() + WALL_LIMIT_S, 0.0
    while time.monotonic() < end and not (completed and disarmed):
        if time.monotonic() > beat:
            gcs.heartbeat()
            beat = time.monotonic() + 1.0
        kinds = ["MISSION_CURRENT", "HEARTBEAT", "EXTENDED_SYS_STATE"]
        msg = gcs.conn.recv_match(type=kinds, blocking=True, timeout=1)
        if msg is None or msg.get_srcSystem() != 1:
            continue
        if msg.get_type() == "EXTENDED_SYS_STATE":
            if not states or states[-1] != msg.landed_state:
                states.append(msg.landed_state)
        elif msg.get_type() == "MISSION_CURRENT":
            completed |= msg.mission_state == d.MISSION_STATE_COMPLETE
        elif msg.base_mode & d.MAV_MODE_FLAG_SAFETY_ARMED:
            armed = True
        else:
            disarmed |= armed
    return completed, disarmed, states


@pytest.mark.timeout(1800)
def test_the_c172_lands_its_qgc_landing_pattern_in_a_crosswind_and_disarms(tmp_path: Path):
    items = checked_plan(PLAN)[0]
    port = free_udp_port()
    proc, namespace, truth_path = start_sim(
        tmp_path, f"udpin://127.0.0.1:{port}", "--aircraft", "c172p", "--wind", "5,0,0",
        "--turbulence", "light", "--duration", "600",
        # Exact lockstep: the flare is flown the same however busy the machine is (fast
        # lockstep, beside another simulation, once touched down at 1.59 m/s, over 1.5).
        "--exact", "--hold-at", f"{HOLD_AT_S:g}",
    )  # fmt: skip
    gcs = GroundStation(port)
    try:
        gcs.connect()
        # Mission progress as often as QGroundControl asks for it while flying a plan.
        gcs.command(d.MAV_CMD_SET_MESSAGE_INTERVAL, d.MAVLINK_MSG_ID_MISSION_CURRENT, 200_000)
        gcs.command(d.MAV_CMD_SET_MESSAGE_INTERVAL, d.MAVLINK_MSG_ID_EXTENDED_SYS_STATE, 200_000)
        _upload(gcs, items)
        _wait_for_the_hold(proc)
        _command_until_accepted(gcs, d.MAV_CMD_COMPONENT_ARM_DISARM, 1.0)
        _command_until_accepted(gcs, d.MAV_CMD_MISSION_START, 0.0)
        completed, disarmed, states = _fly(gcs)
    except BaseException:
        # The flight never began or broke off: end the run now rather than wait out its
        # hang guard, and fail with what went wrong (the run's output is in the log file).
        stop_tree(proc, namespace)
        raise
    finally:
        gcs.close()
    out = finish(proc, namespace, WALL_LIMIT_S)
    assert completed and disarmed, out[-3000:]
    # What QGroundControl's Fly view goes by (Land Abort only while LANDING): the take-off
    # from the roll to its height, the flight, the landing to the stop, on the ground.
    flown = [d.MAV_LANDED_STATE_TAKEOFF, d.MAV_LANDED_STATE_IN_AIR, d.MAV_LANDED_STATE_LANDING]
    assert states[states.index(flown[0]) :][:4] == [*flown, d.MAV_LANDED_STATE_ON_GROUND], states
    score = landing_score_for_plan(read_truth(truth_path), items)
    # Issue 42's limits (15 m along, 2 m across) with issue 24's: this flight touched down
    # 9 m short when the campaign flew it (benchmarks/landing.py).
    assert score.passed(), score
    # The simulated TFmini was in range: the flare flew on its height, not the navigator's.
    used = re.search(r"disarming \((\d+) landing steps on the rangefinder's height\)", out)
    assert used is not None and int(used.group(1)) > 0, out[-3000:]
    # ... and the flight log has its readings (the logger records every channel by default):
    # in range from the approach down to the wheels.
    ranges = ULog(str(truth_path.with_suffix(".ulg")), ["sensors_range"])
    data = ranges.get_dataset("sensors_range").data
    valid = data["distance_m"][data["valid"] == 1]
    assert len(valid) > 100 and valid.min() < 3.0, (len(valid), valid.min(initial=99))
