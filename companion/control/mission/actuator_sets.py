"""Generic payload outputs, as PX4's "Peripheral via Actuator Set 1-6": DO_SET_ACTUATOR
sets up to six of them at once, from a mission (QGroundControl's "Set actuator") or from a
ground station (MAVSDK's ``Action.set_actuator``).

``ACT_SETn_OUT`` wires actuator set n to a servo card output (0: not wired), where PX4 gives
the output the function "Peripheral via Actuator Set n". DO_SET_ACTUATOR's param1-6 are
sets 1-6, each -1 to 1 or NaN for "leave it": -1 is the card's 1000 µs, 0 its 1500 µs, 1
its 2000 µs (PX4's default output range). param7 (the index) must be 0: there are no sets 7
and above. In a mission item sets 5 and 6 ride in x and y (``items.actuator_values``).

A value for a set that is not wired is passed over, as PX4 passes over a set no output has
(QGroundControl's item sends sets 5 and 6 as 0); a command none of whose values reaches an
output is refused, and so is one that would move an output driving a surface.

Pure: values in, the outputs and their pulses out; the flight controller's plug-in hands
them to the servo output and answers the ground station.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from companion.control.mission.items import MissionItem, actuator_values
from companion.control.mission.servo_payload import ServoPayload
from companion.messages import ACTUATOR_SEQ, VehicleCommand
from companion.params import ParamDecl, declared_values
from mavlink_dialect import companion as d

log = logging.getLogger("companion.actuator_sets")

SETS = 6
CENTRE_US, HALF_RANGE_US = 1500.0, 500.0  # -1..1 onto the card's 1000-2000 µs
ACTUATOR_PARAMS = tuple(
    ParamDecl(f"ACT_SET{n}_OUT", 0.0, 0.0, 8.0, "",
              f"The servo card output actuator set {n} drives (DO_SET_ACTUATOR's param{n}), "
              "numbered from 1 as DO_SET_SERVO numbers them; 0: not wired (PX4: the output "
              f"whose function is Peripheral via Actuator Set {n})")
    for n in range(1, SETS + 1)
)  # fmt: skip


def pulse_us(value: float) -> int:
    """The pulse for an actuator value from -1 to 1."""
    return round(CENTRE_US + HALF_RANGE_US * value)


@dataclass(frozen=True)
class ActuatorSetConfig:
    """Each set's output (0: not wired), set 1 first."""

    outputs: tuple[int, ...] = (0,) * SETS

    @classmethod
    def from_params(cls, values: Mapping[str, float]) -> ActuatorSetConfig:
        v = declared_values(ACTUATOR_PARAMS, values)
        return cls(tuple(round(v[p.name]) for p in ACTUATOR_PARAMS))

    def moves(
        self, values: Sequence[float], index: int, surfaces: Mapping[int, str]
    ) -> tuple[list[tuple[int, int]], str | None]:
        """The (output, pulse) pairs ``values`` (sets 1-6, NaN: leave) ask for, or why
        none are made."""
        if index != 0:
            return [], f"Set actuator: index {index}: only sets 1-6 (index 0) exist"
        moves, unwired = [], []
        for n, (output, value) in enumerate(zip(self.outputs, values, strict=False), 1):
            if math.isnan(value):
                continue
            if output == 0:
                unwired.append(n)
                continue
            surface = surfaces.get(output)
            if surface is not None:
                return [], f"Set actuator: ACT_SET{n}_OUT {output} drives the {surface}"
            moves.append((output, pulse_us(value)))
        if not unwired and not moves:
            return [], "Set actuator: no value given (all NaN)"
        if not moves:
            named = ", ".join(f"ACT_SET{n}_OUT" for n in unwired)
            return [], f"Set actuator: not wired ({named} {'is' if len(unwired) == 1 else 'are'} 0)"
        return moves, None


class ActuatorSets(ServoPayload):
    """DO_SET_ACTUATOR in, the servo output's commands out, the operator told."""

    ITEM = d.MAV_CMD_DO_SET_ACTUATOR
    config = ActuatorSetConfig()

    def configure(self, values: Mapping[str, float]) -> None:
        """The ACT_SETn_OUT parameters' values (at start and on every change)."""
        self.config = ActuatorSetConfig.from_params(values)

    def outputs(self) -> dict[int, str]:
        """The outputs its wired sets drive."""
        wired = enumerate(self.config.outputs, 1)
        return {output: f"actuator set {n}" for n, output in wired if output}

    def act(self, t_us: int, values: Sequence[float], index: int) -> str | None:
        """Each wired set's output to its pulse, handed to the servo output; or why not
        (nothing moves)."""
        moves, problem = self.config.moves(values, index, self.surface_outputs)
        if problem is not None:
            return problem
        for output, pulse in moves:
            self.command(VehicleCommand.set_servo(t_us, ACTUATOR_SEQ, output, pulse))
        text = ", ".join(f"output {o} {p} us" for o, p in moves)
        log.info("actuator sets: %s", text)
        self.say(t_us, d.MAV_SEVERITY_INFO, f"Set actuator: {text}")
        return None

    def item_act(self, t_us: int, item: MissionItem) -> str | None:
        return self.act(t_us, actuator_values(item), round(item.z))
