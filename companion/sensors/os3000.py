"""Ocean-Server OS-3000/OS-5000 digital compass: the ``$C`` sentence into bus messages.

``$C<heading>P<pitch>R<roll>T<temp>[D<depth>][M<|m|>][Mx<>My<>Mz<>][A<|a|>][Ax<>Ay<>Az<>]*hh``
in that order, any of the fields after R optional; ``hh`` is the XOR of the characters
between ``$`` and ``*`` in two hex digits. Angles are degrees as the compass reports them.

Units and axes (OS5000 Compass Manual, "$C" format):
- Mx/My/Mz are "calibrated to milligauss" (only after the user's field-strength
  calibration; raw counts before it), so the scale is a setting, 1e-3 gauss per unit.
- Ax/Ay/Az are in g and read +1 g on z when level and upright: the manual's example
  ``P2.5R-14.0 … Ax0.045Ay-0.245Az0.977`` is the specific force in axes x forward,
  y left, z up (x = +sin 2.5°, y = -sin 14.0°, z = +cos). Body FRD is x forward, y right,
  z down, so y and z change sign: level and still gives az ≈ -9.81 m/s², the IMU
  convention of ``messages.Imu``. The magnetometer shares the board's axes and gets the
  same signs. Both are settings for a compass mounted another way.
Pure: no port, no clock; ``decode`` never raises.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from companion.messages import Compass, Magnetometer
from companion.sensors.ascii_sentence import sentence_text, xor8

STANDARD_GRAVITY_M_S2 = 9.80665
MILLIGAUSS = 1e-3
OS5000_TO_FRD = (1.0, -1.0, -1.0)  # device axes forward-left-up → body forward-right-down
_TOKEN = re.compile(r"(Mx|My|Mz|Ax|Ay|Az|[PRTDMA])?([+-]?(?:\d+(?:\.\d*)?|\.\d+))")
_ORDER = ("", "P", "R", "T", "D", "M", "Mx", "My", "Mz", "A", "Ax", "Ay", "Az")
_RANGES = {"": (0.0, 360.0), "P": (-90.0, 90.0), "R": (-180.0, 180.0)}


@dataclass
class Os3000Counters:
    """What the decoder has seen since it was made."""

    ok: int = 0
    bad_checksum: int = 0
    garbage: int = 0  # not a $C sentence, truncated, or fields out of order or range


@dataclass(frozen=True)
class Os3000Reading:
    """One ``$C`` sentence: the attitude, and the raw vectors when the compass sends them."""

    compass: Compass
    mag: Magnetometer | None  # when Mx, My and Mz are all present; gauss, body FRD
    accel_m_s2: tuple[float, float, float] | None  # specific force, body FRD


class Os3000Decoder:
    """``$C`` sentences into readings; rejects are counted, never raised."""

    def __init__(
        self,
        mag_gauss_per_unit: float = MILLIGAUSS,
        axis_signs: tuple[float, float, float] = OS5000_TO_FRD,
    ) -> None:
        self.mag_gauss_per_unit = mag_gauss_per_unit
        self.axis_signs = axis_signs
        self.counters = Os3000Counters()

    def decode(self, sentence: bytes | str, t_us: int) -> Os3000Reading | None:
        """One sentence (line ending optional) received at ``t_us``."""
        body = self._checked_body(sentence)
        if body is None:
            return None
        fields = _fields(body)
        if fields is None:
            self.counters.garbage += 1
            return None
        self.counters.ok += 1
        compass = Compass(
            t_us,
            math.radians(fields[""]) % (2 * math.pi),
            math.radians(fields["P"]),
            math.radians(fields["R"]),
            fields.get("T", math.nan),
        )
        mag = self._vector(fields, "M", self.mag_gauss_per_unit)
        accel = self._vector(fields, "A", STANDARD_GRAVITY_M_S2)
        return Os3000Reading(compass, None if mag is None else Magnetometer(t_us, *mag), accel)

    def _checked_body(self, sentence: bytes | str) -> str | None:
        """The text after ``$C`` when the sentence is whole and its checksum right."""
        text = sentence_text(sentence)
        body, star, checksum = text[1:].rpartition("*")
        if not text.startswith("$C") or not star or not _is_hex2(checksum):
            self.counters.garbage += 1
            return None
        if xor8(body) != int(checksum, 16):
            self.counters.bad_checksum += 1
            return None
        return body[1:]

    def _vector(
        self, fields: dict[str, float], tag: str, scale: float
    ) -> tuple[float, float, float] | None:
        values = [fields.get(tag + axis) for axis in "xyz"]
        if any(v is None for v in values):
            return None
        sx, sy, sz = self.axis_signs
        x, y, z = (scale * v for v in values if v is not None)
        return (sx * x, sy * y, sz * z)


def _is_hex2(text: str) -> bool:
    return len(text) == 2 and all(ch in "0123456789abcdefABCDEF" for ch in text)


def _fields(body: str) -> dict[str, float] | None:
    """Tag → value for a well-formed body (heading first, tags in order, once each)."""
    fields: dict[str, float] = {}
    position, last = 0, -1
    for match in _TOKEN.finditer(body):
        tag = match.group(1) or ""
        if match.start() != position or _ORDER.index(tag) <= last:
            return None
        position, last = match.end(), _ORDER.index(tag)
        fields[tag] = float(match.group(2))
        if not math.isfinite(fields[tag]):  # hundreds of digits overflow to inf
            return None
    if position != len(body) or not all(tag in fields for tag in _RANGES):
        return None
    for tag, (low, high) in _RANGES.items():
        if not low <= fields[tag] <= high:
            return None
    return fields
