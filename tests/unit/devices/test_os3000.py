"""OS-3000 `$C` sentences: values, optional fields, checksums, truncation, fuzz."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from companion.devices.os3000 import G, Os3000Decoder


def sentence(body: str) -> str:
    """An independent writer: XOR of the characters between '$' and '*'."""
    checksum = 0
    for char in body:
        checksum ^= ord(char)
    return f"${body}*{checksum:02X}"


def test_heading_pitch_roll_temperature():
    dec = Os3000Decoder()
    reading = dec.decode(sentence("C271.5P-3.2R12.8T24.5"), 42)
    c = reading.compass
    assert c.t_us == 42 and c.heading_rad == pytest.approx(math.radians(271.5))
    assert c.pitch_rad == pytest.approx(math.radians(-3.2))
    assert c.roll_rad == pytest.approx(math.radians(12.8)) and c.temp_c == 24.5
    assert reading.mag is None and reading.accel is None and dec.counters.ok == 1


def test_optional_magnetometer_and_accelerometer_fields():
    reading = Os3000Decoder().decode(
        sentence("C10.0P0.0R0.0T20.0Mx210.5My-50.0Mz-480.0Ax0.010Ay-0.020Az1.000"), 7
    )
    assert reading.mag.mx_gauss == pytest.approx(0.2105) and reading.mag.mz_gauss == -0.48
    assert reading.accel.az_m_s2 == pytest.approx(-G)  # level: specific force -g, body FRD
    assert reading.accel.ax_m_s2 == pytest.approx(-0.01 * G)
    assert math.isnan(reading.accel.gx_rad_s)


def test_bad_checksum_truncation_and_unknown_fields_are_counted():
    dec = Os3000Decoder()
    good = sentence("C100.0P1.0R2.0T20.0")
    assert dec.decode(good[:-2] + ("00" if good[-2:] != "00" else "01"), 0) is None
    assert dec.decode(good[:12], 0) is None
    assert dec.decode(sentence("C100.0P1.0R2.0X9"), 0) is None
    assert dec.decode(sentence("C400.0P1.0R2.0"), 0) is None  # heading out of range
    c = dec.counters
    assert (c.ok, c.bad_checksum, c.garbage) == (0, 1, 3)


@given(st.text(max_size=80))
def test_any_text_never_raises(text):
    Os3000Decoder().decode("$" + text, 0)
