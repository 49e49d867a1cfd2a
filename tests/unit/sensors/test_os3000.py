"""The OS-3000/OS-5000 ``$C`` sentence: values, optional fields, units, axes, rejects."""

from __future__ import annotations

import math
from functools import reduce

import pytest
from hypothesis import given
from hypothesis import strategies as st

from companion.sensors.os3000 import Os3000Decoder

G = 9.80665
# The two examples printed in the OS5000 Compass Manual, checksums as printed there.
MANUAL_SHORT = "$C320.5P0.2R-18.3T19.0*3C"
MANUAL_FULL = "$C212.4P2.5R-14.0T28.4Mx107977.90My-79422.00Mz173.27Ax0.045Ay-0.245Az0.977*3A"


def sentence(text: str) -> str:
    """``$<text>*hh`` with the XOR checksum, computed here (an independent writer)."""
    return f"${text}*{reduce(lambda acc, ch: acc ^ ord(ch), text, 0):02X}"


def os3000(body: str) -> str:
    """A ``$C`` sentence around ``body`` (heading onwards)."""
    return sentence("C" + body)


def counts(dec: Os3000Decoder) -> tuple[int, int, int]:
    return dec.counters.ok, dec.counters.bad_checksum, dec.counters.garbage


def test_the_factory_format_gives_the_compass_message():
    dec = Os3000Decoder()
    reading = dec.decode(MANUAL_SHORT + "\r\n", 1234)
    c = reading.compass
    assert c.t_us == 1234 and c.temp_c == 19.0
    assert c.heading_rad == pytest.approx(math.radians(320.5), abs=1e-12)
    assert c.pitch_rad == pytest.approx(math.radians(0.2), abs=1e-12)
    assert c.roll_rad == pytest.approx(math.radians(-18.3), abs=1e-12)
    assert reading.mag is None and reading.accel_m_s2 is None
    assert counts(dec) == (1, 0, 0)


def test_magnetometer_in_gauss_and_accel_as_frd_specific_force():
    reading = Os3000Decoder().decode(MANUAL_FULL.encode(), 7)
    mag = reading.mag
    assert mag.t_us == 7
    assert (mag.mx_gauss, mag.my_gauss, mag.mz_gauss) == pytest.approx((107.9779, 79.422, -0.17327))
    # Pitched up 2.5°, rolled left 14°: specific force forward +, right +, down -.
    assert reading.accel_m_s2 == pytest.approx((0.045 * G, 0.245 * G, -0.977 * G))


def test_level_and_still_reads_minus_g_on_z_like_the_imu():
    reading = Os3000Decoder().decode(os3000("90.0P0.0R0.0T20.0Ax0.000Ay0.000Az1.000"), 0)
    assert reading.accel_m_s2 == pytest.approx((0.0, 0.0, -G))


@pytest.mark.parametrize(
    ("fields", "has_mag", "has_accel"),
    [
        ("Mx100.0My-200.0Mz300.0", True, False),
        ("Ax0.1Ay0.2Az0.9", False, True),
        ("D21.01M512.3A1.001", False, False),  # depth and the scalar magnitudes only
        ("Mx100.0My-200.0", False, False),  # an incomplete vector is no vector
        ("D3.5Mx1My2Mz3A1.0Ax0Ay0Az1", True, True),
    ],
)
def test_optional_fields_in_any_subset(fields, has_mag, has_accel):
    reading = Os3000Decoder().decode(os3000("10.0P1.0R2.0T20.0" + fields), 0)
    assert (reading.mag is not None, reading.accel_m_s2 is not None) == (has_mag, has_accel)


def test_temperature_is_optional_and_heading_360_is_north():
    reading = Os3000Decoder().decode(os3000("360.0P-90R180"), 0)
    assert reading.compass.heading_rad == 0.0 and math.isnan(reading.compass.temp_c)
    assert reading.compass.roll_rad == pytest.approx(math.pi)


def test_the_magnetometer_unit_and_axes_are_settings():
    dec = Os3000Decoder(mag_gauss_per_unit=1.0, axis_signs=(1.0, 1.0, 1.0))
    mag = dec.decode(os3000("0P0R0Mx0.2My-0.1Mz0.4"), 0).mag
    assert (mag.mx_gauss, mag.my_gauss, mag.mz_gauss) == (0.2, -0.1, 0.4)


def test_lower_case_checksum_digits_are_accepted():
    sentence = os3000("12.5P1R2T3")
    assert Os3000Decoder().decode(sentence[:-2] + sentence[-2:].lower(), 0) is not None


def test_wrong_checksums_are_counted():
    dec = Os3000Decoder()
    assert dec.decode(MANUAL_SHORT[:-2] + "3D", 0) is None
    assert dec.decode(MANUAL_SHORT.replace("320.5", "321.5"), 0) is None
    assert counts(dec) == (0, 2, 0)


def test_every_truncation_is_garbage():
    dec = Os3000Decoder()
    for cut in range(len(MANUAL_FULL)):
        assert dec.decode(MANUAL_FULL[:cut], 0) is None
    assert counts(dec) == (0, 0, len(MANUAL_FULL))


@pytest.mark.parametrize(
    "body",
    [
        "P1.0R2.0T3.0",  # no heading
        "10.0R2.0T3.0",  # no pitch
        "10.0P1.0",  # no roll
        "10.0R2.0P1.0",  # out of order
        "10.0P1.0R2.0T3.0T4.0",  # twice
        "10.0P1.0R2.0Q5",  # unknown field
        "10.0P91.0R2.0",
        "361.0P1.0R2.0",
        "10.0P1.0R2.0T" + "9" * 400,  # overflows to infinity
        "10.0P1.0R2.0T1.2.3",
        "10.0 P1.0R2.0",
    ],
)
def test_malformed_bodies_are_garbage(body):
    dec = Os3000Decoder()
    assert dec.decode(os3000(body), 0) is None
    assert counts(dec) == (0, 0, 1)


@pytest.mark.parametrize(
    "junk", [b"", b"\xff$C1P2R3*00", "$GPGGA,1*00", "C10P1R2*00", "$C1P2R3*G0"]
)
def test_junk_is_garbage(junk):
    dec = Os3000Decoder()
    assert dec.decode(junk, 0) is None
    assert counts(dec) == (0, 0, 1)


@given(st.lists(st.one_of(st.text(max_size=80), st.binary(max_size=80)), max_size=20))
def test_any_input_never_raises(inputs):
    dec = Os3000Decoder()
    for item in inputs:
        dec.decode(item, 0)
    assert sum(counts(dec)) == len(inputs)


@given(st.text(alphabet="0123456789.-+PRTDMAxyzQ", max_size=60))
def test_checksummed_random_bodies_never_raise(body):
    dec = Os3000Decoder()
    reading = dec.decode(os3000(body), 0)
    assert sum(counts(dec)) == 1
    if reading is not None:
        assert 0.0 <= reading.compass.heading_rad < 2 * math.pi
