"""The Ocean-Server OS-3000/OS-5000 digital compass sentence.

``$C<heading>P<pitch>R<roll>T<temp>*<xx>``, optionally with ``Mx<..>My<..>Mz<..>`` and
``Ax<..>Ay<..>Az<..>`` before the ``*``; ``xx`` is the XOR of the characters between ``$``
and ``*`` in two hex digits. Angles are degrees. Magnetic field: milligauss by default (a
setting: some firmware reports other units). Acceleration is reported in g and becomes
specific force in body FRD m/s², the IMU convention (level and still: az ≈ -9.81), which
is why the compass's +1 g on a level z axis is negated.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from companion.messages import Compass, Imu, Magnetometer

G = 9.80665
_FIELD = re.compile(r"(Mx|My|Mz|Ax|Ay|Az|C|P|R|T)(-?\d+(?:\.\d+)?)")


@dataclass
class Os3000Counters:
    ok: int = 0
    bad_checksum: int = 0
    garbage: int = 0


@dataclass
class Os3000Reading:
    compass: Compass
    mag: Magnetometer | None = None
    accel: Imu | None = None  # accelerometer only: gyro fields are NaN


class Os3000Decoder:
    """Pure: one sentence and its reception time in, a reading or a counted reject out."""

    def __init__(self, mag_unit_gauss: float = 1e-3) -> None:
        self.mag_unit_gauss = mag_unit_gauss
        self.counters = Os3000Counters()

    def decode(self, sentence: bytes | str, t_us: int) -> Os3000Reading | None:
        text = sentence.decode("ascii", "replace") if isinstance(sentence, bytes) else sentence
        text = text.strip()
        body, star, checksum = text.partition("*")
        if not body.startswith("$C") or not star or len(checksum) != 2:
            self.counters.garbage += 1
            return None
        expected = 0
        for char in body[1:]:
            expected ^= ord(char)
        try:
            if int(checksum, 16) != expected:
                self.counters.bad_checksum += 1
                return None
        except ValueError:
            self.counters.garbage += 1
            return None
        reading = self._fields(body[1:], t_us)
        if reading is None:
            self.counters.garbage += 1
        else:
            self.counters.ok += 1
        return reading

    def _fields(self, body: str, t_us: int) -> Os3000Reading | None:
        matches = _FIELD.findall(body)
        if "".join(k + v for k, v in matches) != body:
            return None  # something in the sentence that is not a known field
        values = {key: float(value) for key, value in matches}
        if not {"C", "P", "R"} <= values.keys() or not 0.0 <= values["C"] <= 360.0:
            return None
        compass = Compass(
            t_us,
            math.radians(values["C"]) % (2 * math.pi),
            math.radians(values["P"]),
            math.radians(values["R"]),
            values.get("T", math.nan),
        )
        reading = Os3000Reading(compass)
        if {"Mx", "My", "Mz"} <= values.keys():
            unit = self.mag_unit_gauss
            reading.mag = Magnetometer(
                t_us, values["Mx"] * unit, values["My"] * unit, values["Mz"] * unit
            )
        if {"Ax", "Ay", "Az"} <= values.keys():
            ax, ay, az = (-values[k] * G for k in ("Ax", "Ay", "Az"))
            reading.accel = Imu(
                t_us, ax, ay, az, math.nan, math.nan, math.nan, values.get("T", math.nan)
            )
        return reading
