"""A payload gripper on a servo output, as ArduPilot's servo gripper (``GRIP_TYPE`` 1):
DO_GRIPPER grabs or releases, from a mission (QGroundControl's "Gripper Mechanism") or from
a ground station (MAVSDK's Gripper plug-in, ``grab`` and ``release``).

Each action sets the output to ``GRIP_GRAB`` or ``GRIP_RELEASE`` and holds it there, as a
hobby servo holds a latch; nothing moves the output before the first action. There is one
gripper: DO_GRIPPER's param1 (which gripper) is not read, as ArduPilot does not read it.

Pure: an action in, the output and the pulse out; the flight controller's plug-in hands
them to the servo output and answers the ground station.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass

from companion.control.mission.items import MissionItem
from companion.control.mission.servo_payload import ServoPayload
from companion.messages import GRIPPER_SEQ, VehicleCommand
from companion.params import ParamDecl, declared_values
from mavlink_dialect import companion as d

log = logging.getLogger("companion.gripper")

ENABLE_PARAM = "GRIP_ENABLE"
RELEASE, GRAB = 0, 1  # DO_GRIPPER's param2 (MAVLink's GRIPPER_ACTIONS)
ACTION_NAMES = {RELEASE: "release", GRAB: "grab"}
GRIPPER_PARAMS = (
    ParamDecl(ENABLE_PARAM, 0.0, values=((0.0, "Disabled"), (1.0, "Enabled")),
              doc="Whether a gripper is wired to GRIP_OUTPUT (DO_GRIPPER is refused, and "
                  "passed over in a mission, while it is not)"),
    ParamDecl("GRIP_OUTPUT", 8.0, 1.0, 8.0, "",
              "The servo card output the gripper is wired to, numbered from 1 as "
              "DO_SET_SERVO numbers them (ArduPilot: the output whose SERVOn_FUNCTION is 28)"),
    ParamDecl("GRIP_GRAB", 1900.0, 1000.0, 2000.0, "us", "The pulse that closes the gripper"),
    ParamDecl("GRIP_RELEASE", 1100.0, 1000.0, 2000.0, "us",
              "The pulse that opens the gripper and lets the payload go"),
)  # fmt: skip


@dataclass(frozen=True)
class GripperConfig:
    """The gripper's parameters, grouped."""

    enabled: bool = False
    output: int = 8
    grab_us: int = 1900
    release_us: int = 1100

    @classmethod
    def from_params(cls, values: Mapping[str, float]) -> GripperConfig:
        v = declared_values(GRIPPER_PARAMS, values)
        return cls(
            v[ENABLE_PARAM] == 1.0, round(v["GRIP_OUTPUT"]), round(v["GRIP_GRAB"]),
            round(v["GRIP_RELEASE"]),
        )  # fmt: skip

    def pulse(self, action: int) -> tuple[int, int]:
        """The output and the pulse that do ``action`` (GRAB or RELEASE)."""
        return self.output, self.grab_us if action == GRAB else self.release_us

    def refusal(self, action: int, surfaces: Mapping[int, str]) -> str | None:
        """Why ``action`` cannot be done (a ground station's STATUSTEXT), or None."""
        if not self.enabled:
            return f"Gripper: not set up ({ENABLE_PARAM} is 0)"
        if action not in ACTION_NAMES:
            return f"Gripper: action {action} is neither release (0) nor grab (1)"
        surface = surfaces.get(self.output)
        if surface is not None:
            return f"Gripper: GRIP_OUTPUT {self.output} drives the {surface}"
        return None


class Gripper(ServoPayload):
    """DO_GRIPPER actions in, the servo output's commands out, the operator told."""

    ITEM = d.MAV_CMD_DO_GRIPPER
    config = GripperConfig()

    def configure(self, values: Mapping[str, float]) -> None:
        """The GRIP_* parameters' values (at start and on every change)."""
        self.config = GripperConfig.from_params(values)

    def outputs(self) -> dict[int, str]:
        """The output it drives once set up."""
        return {self.config.output: "gripper"} if self.config.enabled else {}

    def act(self, t_us: int, action: int) -> str | None:
        """Grab or release: the pulse handed to the servo output and the operator told;
        or why not (nothing moves)."""
        problem = self.config.refusal(action, self.surface_outputs)
        if problem is not None:
            return problem
        output, pulse = self.config.pulse(action)
        self.command(VehicleCommand.set_servo(t_us, GRIPPER_SEQ, output, pulse))
        log.info("gripper: %s (output %d to %d us)", ACTION_NAMES[action], output, pulse)
        self.say(t_us, d.MAV_SEVERITY_INFO, f"Gripper: {ACTION_NAMES[action]}")
        return None

    def item_act(self, t_us: int, item: MissionItem) -> str | None:
        return self.act(t_us, round(item.param2))
