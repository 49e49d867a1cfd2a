"""What a payload on a servo card output shares, whatever it is (a gripper, actuator sets):
the way to hand a pulse to the servo output, to tell the operator, the outputs it must not
touch, and how a mission's items for it are carried out.

Pure: the flight controller's plug-in gives it the two callables and takes nothing back
but the refusals' texts.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping, Sequence
from typing import ClassVar, Protocol

from companion.control.mission.items import MissionItem
from companion.messages import VehicleCommand
from mavlink_dialect import companion as d

log = logging.getLogger("companion.servo_payload")


class DrivesOutputs(Protocol):
    """A payload configured from the parameters, which then says which outputs they give
    it and is told which it must not drive."""

    surface_outputs: Mapping[int, str]

    def configure(self, values: Mapping[str, float]) -> None: ...

    def outputs(self) -> dict[int, str]: ...


def configure_payloads(
    payloads: Sequence[DrivesOutputs], values: Mapping[str, float], surfaces: Mapping[int, str]
) -> None:
    """Each payload configured from ``values``, then given the outputs it must not drive
    (output: what drives it): the airframe's surfaces and every other payload's. An output
    drives one thing, as an ArduPilot or PX4 output has one function: a gripper and a light
    on one output would drop the payload when the light is switched."""
    for payload in payloads:
        payload.configure(values)
    claims = [p.outputs() for p in payloads]
    for i, payload in enumerate(payloads):
        others = {o: what for j, c in enumerate(claims) if j != i for o, what in c.items()}
        payload.surface_outputs = {**others, **surfaces}


class ServoPayload:
    """A payload's mission items and commands in, the servo output's commands out."""

    ITEM: ClassVar[int]  # the MAV_CMD of its mission items

    def __init__(
        self,
        command: Callable[[VehicleCommand], None],
        say: Callable[[int, int, str], None],
        surface_outputs: Mapping[int, str],
    ) -> None:
        self.command = command  # a pulse for the servo output (on link/commands)
        self.say = say  # (t_us, MAV_SEVERITY, text) for the operator
        # Output (from 1): the surface or other payload that drives it (configure_payloads).
        self.surface_outputs = surface_outputs

    def item_act(self, t_us: int, item: MissionItem) -> str | None:
        """Carry out one of its mission items; why not (nothing moves)."""
        raise NotImplementedError

    def items(self, t_us: int, items: Sequence[MissionItem]) -> None:
        """Its items among those a mission passed: each done, or the operator told why not
        (the mission flies on, as it does past a servo it may not set)."""
        for item in items:
            if item.command == self.ITEM:
                problem = self.item_act(t_us, item)
                if problem is not None:
                    log.warning("mission item %d: %s", item.seq, problem)
                    self.say(t_us, d.MAV_SEVERITY_WARNING, f"Mission: {problem}")
