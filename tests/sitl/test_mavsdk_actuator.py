"""A generic payload output worked as a PX4 user works it: MAVSDK's ``Action.set_actuator``
and QGroundControl's "Set actuator" mission item (MAV_CMD_DO_SET_ACTUATOR).

``ACT_SET1_OUT`` (set by MAVSDK's Param plug-in, as a user sets it in QGroundControl) wires
actuator set 1 to output 7 of the c172p's Mini SSC (its spare servo 6). 1 is 2000 µs and -1
1000 µs, read back from SERVO_OUTPUT_RAW, which the servo output sends after writing the
card. Disarmed (the servo output runs only armed) the command is refused, and MAVSDK says
so.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from mavsdk.asyncio.plugins.param import ParamAsync
from mavsdk.plugins.action import ActionError

from mavlink_dialect import companion as d
from tests.sim.sim_run import with_sim
from tests.support.mavsdk_flight import payload_worked, plan_uploaded
from tests.support.qgc_plan import HOME, A, item_at_a_plan


def _plan(path: Path) -> Path:
    """Take-off, waypoint A, "Set actuator" with actuator 1 at -1 and the others left (as
    QGroundControl 4.4.5 saves it: frame MISSION, actuators 1-4 in param1-4, null for
    "unchanged"), waypoint B."""
    return item_at_a_plan(path, d.MAV_CMD_DO_SET_ACTUATOR, [-1, None, None, None, 0, 0, 0])


async def _work(port: int, plan: str) -> dict:
    """Refused disarmed; wired, armed and flying: set 1 to 1 by command, then to -1 by the
    plan at A. What MAVSDK saw."""
    seen: dict = {}
    async with plan_uploaded(port, plan) as flight:
        try:
            await flight.action.set_actuator(1, 1.0)
            seen["disarmed"] = "accepted"
        except ActionError as exc:
            seen["disarmed"] = exc.result.name
        await ParamAsync(flight.system).set_param_float("ACT_SET1_OUT", 7.0)
        # Set 1 to 1 on the runway, kilometres before A; the plan's item puts it at -1.
        act = lambda: flight.action.set_actuator(1, 1.0)  # noqa: E731
        seen |= await payload_worked(flight, act, 7, (2000, 1000), (HOME, A))
    return seen


@pytest.mark.timeout(300)
def test_mavsdk_sets_an_actuator_and_a_plans_set_actuator_item_moves_it_back(tmp_path: Path):
    plan = _plan(tmp_path / "actuator.plan")
    seen, out, _truth = with_sim(tmp_path, lambda port: _work(port, str(plan)))
    assert seen["disarmed"] == "COMMAND_DENIED", seen
    assert seen["set_before"] <= 1, seen  # still on the way to A
    assert seen["from_point_m"] < 400.0, seen  # over A (a turn's lead is some 150 m)
    assert out.count("actuator sets: output 7 2000 us") == 1, out[-3000:]
    assert "actuator sets: output 7 1000 us" in out
