"""MANUAL_CONTROL: QGroundControl's joystick and virtual joystick as the pilot's sticks.

The axes are -1000..1000 (``x`` forward = nose down, ``y`` right = roll right, ``r``
twist right = yaw right) and ``z`` the throttle 0..1000, as QGroundControl sends them
for a fixed wing; INT16_MAX marks an axis the joystick does not have (centred, or no
throttle). Anything else out of range, or a message for another system, is refused and
counted (the message has no acknowledgement; the operator reads a rate-limited
STATUSTEXT). Each accepted message becomes a ``PilotInput`` on ``link/manual_control``,
stamped with the vehicle's time when it arrived.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from companion.link.microservice import Outgoing, Peer
from companion.messages import PilotInput, PilotSource

AXIS_INVALID = 32767
JOYSTICK_FRESH_US = 1_000_000
FULL = 1000.0


class ManualControlService:
    """Turns MANUAL_CONTROL into sticks for the controller."""

    handles = frozenset({"MANUAL_CONTROL"})

    def __init__(
        self,
        sysid: int,
        publish: Callable[[PilotInput], None],
        now_us: Callable[[], int],
        on_refusal: Callable[[str], None] | None = None,
    ) -> None:
        self.sysid = sysid
        self.publish = publish
        self.now_us = now_us
        self.on_refusal = on_refusal
        self.accepted = 0
        self.refused = 0
        self.last_us: int | None = None  # when the newest accepted sticks arrived

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        if msg.target != self.sysid:
            return []  # another vehicle's joystick: not ours to fly, not a fault either
        problem = self._problem(msg)
        if problem is not None:
            self.refused += 1
            if self.on_refusal is not None:
                self.on_refusal(f"MANUAL_CONTROL refused: {problem}")
            return []
        sticks = PilotInput(t_us=self.now_us(), source=PilotSource.MANUAL_CONTROL, rssi=255)
        self.last_us = sticks.t_us
        sticks.pitch = -_axis(msg.x)  # stick forward is nose down
        sticks.roll = _axis(msg.y)
        sticks.yaw = _axis(msg.r)
        sticks.throttle = 0.0 if msg.z == AXIS_INVALID else msg.z / FULL
        sticks.mode_switch = -1
        self.publish(sticks)
        self.accepted += 1
        return []

    def tick(self, now_s: float) -> list[Outgoing]:
        return []

    def flying(self, now_us: int) -> bool:
        """Whether a joystick is sending sticks now (a ground station sends them at 10 Hz
        or more while its joystick is on, armed or not)."""
        return self.last_us is not None and now_us - self.last_us < JOYSTICK_FRESH_US

    @staticmethod
    def _problem(msg: Any) -> str | None:
        for name in ("x", "y", "r"):
            value = getattr(msg, name)
            if value != AXIS_INVALID and not -FULL <= value <= FULL:
                return f"{name} {value} outside [-1000, 1000]"
        if msg.z != AXIS_INVALID and not 0 <= msg.z <= FULL:
            return f"z (throttle) {msg.z} outside [0, 1000]"
        return None


def _axis(value: int) -> float:
    return 0.0 if value == AXIS_INVALID else value / FULL
