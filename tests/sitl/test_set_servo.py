"""DO_SET_SERVO as an ArduPilot user sends it (MAVProxy's ``servo set 7 1900``, or a
mission item releasing a payload), flown in lockstep JSBSim with the c172p, whose
airframe drives servos 0-5 of the Mini SSC: outputs 7 and 8 (its servos 6 and 7) are
spare. The pulse is read back from SERVO_OUTPUT_RAW, which the servo output reports after
writing it to the card."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from companion.actuators.minissc import position_for_pulse, pulse_us
from mavlink_dialect import companion as d
from tests.support.vehicle import REPO

PLAN = REPO / "qgc_plans" / "short_leg.plan"
pytestmark = pytest.mark.vehicle(airframe="c172p")


def _with_release(tmp_path: Path) -> Path:
    """short_leg.plan with two DO_SET_SERVO items after its first waypoint: output 8 to
    1200 µs, and output 1 (the aileron's) to 2000 µs, which is not set."""
    plan = json.loads(PLAN.read_text())
    items = plan["mission"]["items"]
    for output, pulse in ((1, 2000), (8, 1200)):
        release = {"type": "SimpleItem", "command": d.MAV_CMD_DO_SET_SERVO, "frame": 2,
                   "autoContinue": True, "params": [output, pulse, 0, 0, 0, 0, 0]}  # fmt: skip
        items.insert(2, release)
    for n, item in enumerate(items, start=1):
        item["doJumpId"] = n
    path = tmp_path / "release.plan"
    path.write_text(json.dumps(plan))
    return path


def _answer(sim, output: int, pulse: int, said: str = "") -> int:
    """The COMMAND_ACK's result for DO_SET_SERVO; with ``said``, the text the vehicle says
    with it too (a refusal's reason comes with its ack, before or after it)."""
    w = sim.watcher
    before = len(w.texts)
    w.mav.command_long_send(1, 1, d.MAV_CMD_DO_SET_SERVO, 0, output, pulse, 0, 0, 0, 0, 0)

    def acked(m):
        return m.get_type() == "COMMAND_ACK" and m.command == d.MAV_CMD_DO_SET_SERVO and m

    result = w.until(acked, 30, "DO_SET_SERVO's ack").result
    if said:
        w.until(lambda _m: any(said in t for t in w.texts[before:]) or None, 30, repr(said))
    return result


def _pulse_shown(sim, output: int, pulse: int) -> None:
    """SERVO_OUTPUT_RAW shows ``output`` at the card's step nearest ``pulse``."""
    field, shown = f"servo{output}_raw", pulse_us(position_for_pulse(pulse))
    sim.watcher.until(
        lambda m: m.get_type() == "SERVO_OUTPUT_RAW" and getattr(m, field) == shown,
        60,
        f"{field} {shown} in SERVO_OUTPUT_RAW",
    )


@pytest.mark.timeout(900)
def test_a_spare_output_is_set_by_command_and_by_mission_and_a_surface_is_refused(sim, tmp_path):
    sim.wait_ready()
    said = "Set servo: the servo output runs only while armed"
    assert _answer(sim, 7, 1900, said) == d.MAV_RESULT_DENIED
    sim.upload_plan(_with_release(tmp_path))
    sim.arm_and_start()
    sim.run_until_item(1)  # in the air, on the leg to the waypoint before the release
    assert _answer(sim, 7, 1900) == d.MAV_RESULT_ACCEPTED
    _pulse_shown(sim, 7, 1900)
    said = "Set servo: output 2 drives the elevator"
    assert _answer(sim, 2, 1500, said) == d.MAV_RESULT_DENIED
    said = "param1 (instance) 9 outside"  # the card has eight
    assert _answer(sim, 9, 1500, said) == d.MAV_RESULT_DENIED
    sim.run_until_item(4)  # past the release items, on to the last waypoint
    _pulse_shown(sim, 8, 1200)
    told = "Mission: output 1 drives the aileron: not set"
    assert any(told in t for t in sim.watcher.texts), sim.watcher.texts[-8:]
    _pulse_shown(sim, 7, 1900)  # the command's output still held
