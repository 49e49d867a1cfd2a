"""VectorNav ASCII ($VNYMR, $VNIMU): values, both checksum kinds, appended fields, rejects."""

from __future__ import annotations

import math
import time
from functools import reduce

import pytest
from hypothesis import given
from hypothesis import strategies as st

from companion.sensors.vectornav import VectorNavDecoder

# The numbers of the manual's register-27 example: a level, still sensor.
YMR = (
    "+006.380,+000.023,-001.953,+1.0640,-0.2531,+3.0614,"
    "+00.005,+00.344,-09.758,-0.001222,-0.000450,-0.001218"
)
IMU = (
    "-02.0841,+00.6045,+02.8911,+00.381,-00.154,-09.657,"
    "-00.005683,+00.002143,-00.001459,+21.6,+099.761"
)


def xor8(text: str) -> str:
    return f"{reduce(lambda acc, ch: acc ^ ord(ch), text, 0):02X}"


def crc16(text: str) -> str:
    """The manual's C routine, transcribed: an independent writer for the 16-bit CRC."""
    crc = 0
    for byte in text.encode():
        crc = ((crc >> 8) | (crc << 8)) & 0xFFFF
        crc ^= byte
        crc ^= (crc & 0xFF) >> 4
        crc ^= (crc << 12) & 0xFFFF
        crc ^= ((crc & 0xFF) << 5) & 0xFFFF
    return f"{crc:04X}"


def vn(payload: str, kind: str = "xor") -> str:
    return f"${payload}*{xor8(payload) if kind == 'xor' else crc16(payload)}"


def counts(dec: VectorNavDecoder) -> tuple[int, int, int, int]:
    c = dec.counters
    return c.ok, c.bad_checksum, c.garbage, c.ignored


def test_the_crc_transcription_matches_the_standard_check_value():
    assert crc16("123456789") == "31C3"  # CRC-16/XMODEM check value


@pytest.mark.parametrize("kind", ["xor", "crc"])
def test_vnymr_gives_attitude_magnetometer_and_imu(kind):
    dec = VectorNavDecoder()
    reading = dec.decode(vn("VNYMR," + YMR, kind) + "\r\n", 99)
    att, mag, imu = reading.attitude, reading.mag, reading.imu
    assert att.yaw_rad == pytest.approx(math.radians(6.380), abs=1e-12)
    assert att.pitch_rad == pytest.approx(math.radians(0.023), abs=1e-12)
    assert att.roll_rad == pytest.approx(math.radians(-1.953), abs=1e-12)
    assert (mag.t_us, mag.mx_gauss, mag.my_gauss, mag.mz_gauss) == (99, 1.064, -0.2531, 3.0614)
    assert (imu.t_us, imu.ax_m_s2, imu.ay_m_s2, imu.az_m_s2) == (99, 0.005, 0.344, -9.758)
    assert (imu.gx_rad_s, imu.gy_rad_s, imu.gz_rad_s) == (-0.001222, -0.00045, -0.001218)
    assert math.isnan(imu.temp_c) and math.isnan(reading.pressure_pa)
    assert counts(dec) == (1, 0, 0, 0)


def test_level_and_still_is_minus_g_on_z_as_the_bus_expects():
    imu = VectorNavDecoder().decode(vn("VNYMR," + YMR), 0).imu
    assert imu.az_m_s2 == pytest.approx(-9.81, abs=0.1) and abs(imu.ax_m_s2) < 0.05


@pytest.mark.parametrize("kind", ["xor", "crc"])
def test_vnimu_gives_temperature_and_pressure(kind):
    reading = VectorNavDecoder().decode(vn("VNIMU," + IMU, kind).encode(), 5)
    assert reading.attitude is None and reading.pressure_pa == pytest.approx(99_761.0)
    assert reading.imu.temp_c == 21.6 and reading.imu.az_m_s2 == -9.657
    assert reading.imu.gy_rad_s == 0.002143 and reading.mag.mx_gauss == -2.0841


def test_appended_counter_and_status_fields_are_accepted():
    dec = VectorNavDecoder()
    assert dec.decode(vn("VNYMR," + YMR + ",T1162704"), 0) is not None
    assert dec.decode(vn("VNIMU," + IMU + ",S0000", "crc"), 0) is not None


def test_lower_case_checksum_digits_are_accepted():
    sentence = vn("VNYMR," + YMR, "crc")
    assert VectorNavDecoder().decode(sentence[:-4] + sentence[-4:].lower(), 0) is not None


@pytest.mark.parametrize("kind", ["xor", "crc"])
def test_wrong_checksums_are_counted(kind):
    dec = VectorNavDecoder()
    good = vn("VNYMR," + YMR, kind)
    assert dec.decode(good[:-1] + ("0" if good[-1] != "0" else "1"), 0) is None
    assert dec.decode(good.replace("+006.380", "+006.381"), 0) is None
    assert counts(dec) == (0, 2, 0, 0)


@pytest.mark.parametrize("placeholder", ["XX", "XXXX", "xx"])
def test_checksum_placeholders_are_counted_as_bad(placeholder):
    dec = VectorNavDecoder()
    assert dec.decode(f"$VNYMR,{YMR}*{placeholder}", 0) is None
    assert counts(dec) == (0, 1, 0, 0)


def test_every_truncation_is_garbage():
    dec = VectorNavDecoder()
    sentence = vn("VNIMU," + IMU, "crc")
    for cut in range(len(sentence)):
        assert dec.decode(sentence[:cut], 0) is None
    # Cut after '*' + two of the four CRC digits, the rest reads as a (wrong) 8-bit sum.
    assert counts(dec) == (0, 1, len(sentence) - 1, 0)


@pytest.mark.parametrize(
    "payload",
    [
        "VNYMR," + YMR.rsplit(",", 1)[0],  # a field short
        "VNYMR," + YMR + ",0.5",  # a field too many
        "VNYMR," + YMR.replace("+006.380", "+186.380"),  # yaw out of range
        "VNYMR," + YMR.replace("+000.023", "+090.5"),  # pitch out of range
        "VNYMR," + YMR.replace("+1.0640", "nan"),
        "VNYMR," + YMR.replace("+1.0640", "1e999"),  # infinity
        "VNYMR," + YMR.replace("+1.0640", ""),
        "VNIMU," + IMU + ",X12",  # not a counter or status field
    ],
)
def test_bad_fields_are_garbage(payload):
    dec = VectorNavDecoder()
    assert dec.decode(vn(payload), 0) is None
    assert counts(dec) == (0, 0, 1, 0)


def test_other_vectornav_sentences_are_ignored():
    dec = VectorNavDecoder()
    for sentence in ("$VNYPR,+010.071,+000.278,-002.026*60", "$VNRRG,11*73", "$VNERR,03*72"):
        assert dec.decode(sentence, 0) is None
    assert counts(dec) == (0, 0, 0, 3)


@pytest.mark.parametrize(
    "junk", [b"", b"\xff$VNYMR,1*00", "$GPGGA,1*7B", "VNYMR,1*00", "$VNYMR,1*0G", "$VNYMR,1*123"]
)
def test_junk_is_garbage(junk):
    dec = VectorNavDecoder()
    assert dec.decode(junk, 0) is None
    assert counts(dec) == (0, 0, 1, 0)


@given(st.lists(st.one_of(st.text(max_size=150), st.binary(max_size=150)), max_size=20))
def test_any_input_never_raises(inputs):
    dec = VectorNavDecoder()
    for item in inputs:
        dec.decode(item, 0)
    assert sum(counts(dec)) == len(inputs)


@given(
    st.sampled_from(["VNYMR", "VNIMU", "VNYPR"]),
    st.lists(st.text(alphabet="0123456789.+-eETSX", max_size=10), max_size=14),
    st.sampled_from(["xor", "crc"]),
)
def test_checksummed_random_fields_never_raise(header, fields, kind):
    dec = VectorNavDecoder()
    reading = dec.decode(vn(",".join([header, *fields]), kind), 0)
    assert sum(counts(dec)) == 1
    assert reading is None or math.isfinite(reading.imu.az_m_s2)


def test_a_sentence_of_long_digit_runs_and_a_bad_field_is_refused_at_once():
    """A right checksum, long runs of digits and one bad field: the field pattern used to
    try every split of every run (0.2 s at 72 characters, doubling every few more); this
    one, 150 characters, would have held the IMU's thread for hours."""
    payload = "VNIMU" + ",1111111111111" * 10 + ",11111111,x"
    dec = VectorNavDecoder()
    started = time.monotonic()
    assert dec.decode(vn(payload), 0) is None
    assert time.monotonic() - started < 1.0  # microseconds; a second is any machine's load
    assert counts(dec) == (0, 0, 1, 0)
