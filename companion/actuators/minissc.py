"""The Mini SSC II wire format: three bytes a servo, ``255, id, position``.

Position 0-254 (255 is the sync byte). In the card's default 90° range the pulse runs
from 1000 µs at 0 to 2000 µs at 254, which is what SERVO_OUTPUT_RAW reports.
Each frame is 30 bits on the wire (8N1), so at 9600 baud one costs 3.1 ms and a cycle
has room for only a few: ``plan_cycle`` sends changed channels first and refreshes the
others only with what room is left. Pure: no port, no clock.
"""

from __future__ import annotations

from collections.abc import Iterable

SYNC = 0xFF
FRAME_BITS = 30
PULSE_MIN_US = 1000
PULSE_SPAN_US = 1000
POSITION_MAX = 254


def frame(servo: int, position: int) -> bytes:
    """One command frame."""
    return frames(((servo, position),))


def frames(plan: Iterable[tuple[int, int]]) -> bytes:
    """``frame`` of each (servo, position) of ``plan``, back to back: one call for a cycle's
    frames (the servo plug-in sends one 50 times a second)."""
    out: list[int] = []
    for servo, position in plan:
        if not 0 <= servo <= SYNC - 1:
            raise ValueError(f"servo id {servo} out of 0-254")
        out += (
            SYNC,
            servo,
            POSITION_MAX if position > POSITION_MAX else (position if position > 0 else 0),
        )
    return bytes(out)


def position_for_pulse(pulse_us: float) -> int:
    """The position whose pulse is nearest ``pulse_us`` (clamped to the card's range)."""
    position = round((pulse_us - PULSE_MIN_US) * POSITION_MAX / PULSE_SPAN_US)
    return max(0, min(POSITION_MAX, position))


def pulse_us(position: int) -> int:
    """The pulse width, in µs, the card puts out for a position (90° range)."""
    return PULSE_MIN_US + round(position * PULSE_SPAN_US / POSITION_MAX)


# Every position's pulse, worked out once: the servo plug-in reports each channel's pulse
# with every answer, 50 times a second.
PULSES_US = tuple(pulse_us(p) for p in range(POSITION_MAX + 1))


def frames_per_second(baud: int) -> float:
    """How many frames the wire carries in a second."""
    return baud / FRAME_BITS


def plan_cycle(
    wanted: dict[int, int], sent: dict[int, int], refresh_order: Iterable[int], room: int
) -> list[tuple[int, int]]:
    """The (servo, position) frames to send this cycle, at most ``room`` of them.

    Channels whose wanted position differs from the last sent come first (in servo order);
    the rest are refreshed in ``refresh_order`` (oldest first) while room is left.
    """
    changed = [s for s in sorted(wanted) if sent.get(s) != wanted[s]]
    plan = changed[: max(0, room)]
    for servo in refresh_order:
        if len(plan) >= room:
            break
        if servo in wanted and servo not in plan:
            plan.append(servo)
    return [(s, wanted[s]) for s in plan]


class FrameDecoder:
    """Byte stream → frames, resynchronising on the sync byte (what the card does)."""

    def __init__(self) -> None:
        self._pending: list[int] = []
        self.frames = 0
        self.garbage = 0  # bytes outside a frame

    def feed(self, data: bytes) -> list[tuple[int, int]]:
        """The complete (servo, position) frames in ``data`` and what came before it."""
        out: list[tuple[int, int]] = []
        for byte in data:
            if byte == SYNC:
                self.garbage += len(self._pending)
                self._pending = [byte]
            elif self._pending:
                self._pending.append(byte)
                if len(self._pending) == 3:
                    out.append((self._pending[1], self._pending[2]))
                    self.frames += 1
                    self._pending = []
            else:
                self.garbage += 1
        return out
