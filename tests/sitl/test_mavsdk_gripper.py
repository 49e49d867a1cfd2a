"""A payload dropped from a gripper, as a MAVSDK script and a QGroundControl plan drop it.

MAVSDK's Gripper plug-in sends DO_GRIPPER (param1 the instance, param2 0 release or 1
grab); QGroundControl's Plan view offers the same command as "Gripper Mechanism". With
``GRIP_ENABLE`` set (by MAVSDK's Param plug-in, as a user sets it in QGroundControl) the
gripper on output 8 of the c172p's Mini SSC (its spare servo 7) grabs at ``GRIP_GRAB`` and
releases at ``GRIP_RELEASE``; the pulse is read back from SERVO_OUTPUT_RAW, which the servo
output sends after writing the card. Disarmed (the servo output runs only armed) the
command is refused, and MAVSDK says so.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from mavsdk.asyncio.plugins.gripper import GripperAsync
from mavsdk.asyncio.plugins.param import ParamAsync
from mavsdk.plugins.gripper import GripperError

from mavlink_dialect import companion as d
from tests.sim.sim_run import with_sim
from tests.support.mavsdk_flight import payload_worked, plan_uploaded
from tests.support.qgc_plan import HOME, A, item_at_a_plan

GRAB_US, RELEASE_US = 1900, 1100  # GRIP_GRAB and GRIP_RELEASE as shipped


def _plan(path: Path) -> Path:
    """Take-off, waypoint A, "Gripper Mechanism" release (as QGroundControl 4.4.5 saves it:
    frame MISSION, param1 the gripper, 1), waypoint B."""
    return item_at_a_plan(path, d.MAV_CMD_DO_GRIPPER, [1, 0, 0, 0, 0, 0, 0])


async def _drop(port: int, plan: str) -> dict:
    """Refused disarmed; set up, armed and flying: grabbed by command, released by the
    plan at A. What MAVSDK saw."""
    seen: dict = {}
    async with plan_uploaded(port, plan) as flight:
        gripper = GripperAsync(flight.system)
        try:
            await gripper.grab(1)
            seen["disarmed"] = "accepted"
        except GripperError as exc:
            seen["disarmed"] = exc.result.name
        await ParamAsync(flight.system).set_param_float("GRIP_ENABLE", 1.0)
        # Grabbed on the runway or climbing out, kilometres before A; the plan releases.
        act = lambda: gripper.grab(1)  # noqa: E731
        seen |= await payload_worked(flight, act, 8, (GRAB_US, RELEASE_US), (HOME, A))
    return seen


@pytest.mark.timeout(300)
def test_a_mavsdk_script_grabs_and_a_plans_gripper_item_releases_the_payload(tmp_path: Path):
    plan = _plan(tmp_path / "drop.plan")
    seen, out, _truth = with_sim(tmp_path, lambda port: _drop(port, str(plan)))
    assert seen["disarmed"] == "FAILED", seen  # MAVSDK's name for DENIED
    assert seen["set_before"] <= 1, seen  # still on the way to A
    # Over A (the c172p flies some 40 m a second; a turn's lead is some 150 m)
    assert seen["from_point_m"] < 400.0, seen
    # Sent right after arming, before the controller listens, and resent by MAVSDK while
    # it waits: done once.
    assert out.count("gripper: grab (output 8 to 1900 us)") == 1, out[-3000:]
    assert "gripper: release (output 8 to 1100 us)" in out
