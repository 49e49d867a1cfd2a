"""NMEA GPS decoding: values to the last digit, epochs in either order, counted rejects."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from companion.devices.line_framer import LineFramer
from companion.devices.nmea_gps import KNOT_M_S, NmeaGpsDecoder
from companion.messages import GpsFixType
from tests.support.nmea import gga, rmc

LAT, LON = -37.9105123, 145.1340456


@pytest.mark.parametrize("talker", ["GP", "GN"])
def test_gga_after_rmc_gives_a_full_fix(talker):
    dec = NmeaGpsDecoder()
    assert dec.decode(rmc("120000.00", "231126", LAT, LON, 40.0, 90.0, talker), 1_000) is None
    fix = dec.decode(gga("120000.00", LAT, LON, 123.4, talker=talker), 2_000)
    assert fix.lat_deg == pytest.approx(LAT, abs=1e-9) and fix.lon_deg == pytest.approx(
        LON, abs=1e-9
    )
    assert fix.alt_msl_m == 123.4 and fix.fix_type == GpsFixType.FIX_3D and fix.satellites == 9
    assert fix.ground_speed_m_s == pytest.approx(40 * KNOT_M_S)
    assert fix.ve_m_s == pytest.approx(40 * KNOT_M_S) and abs(fix.vn_m_s) < 1e-9
    assert fix.utc_us == 1795435200 * 1_000_000 and fix.t_us == 2_000
    assert math.isnan(fix.vd_m_s)


def test_vertical_speed_uses_the_real_interval_and_midnight():
    dec = NmeaGpsDecoder()
    dec.decode(gga("235959.80", LAT, LON, 100.0), 0)
    fix = dec.decode(gga("000000.00", LAT, LON, 101.0), 200_000)  # 0.2 s later, next day
    assert fix.vd_m_s == pytest.approx(-5.0)
    fix = dec.decode(gga("000001.00", LAT, LON, 100.0), 1_200_000)
    assert fix.vd_m_s == pytest.approx(1.0)
    fix = dec.decode(gga("000010.00", LAT, LON, 100.0), 10_000_000)  # a 9 s gap: unknown
    assert math.isnan(fix.vd_m_s)


def test_rmc_only_receivers_get_2d_fixes_and_quality_codes_map():
    dec = NmeaGpsDecoder()
    assert dec.decode(rmc("115959.00", "231126", LAT, LON, 10.0, 0.0), 0) is None
    fix = dec.decode(rmc("120000.00", "231126", LAT, LON, 10.0, 0.0), 0)
    assert fix.fix_type == GpsFixType.FIX_2D and fix.vn_m_s == pytest.approx(10 * KNOT_M_S)
    for quality, kind in ((0, GpsFixType.NO_FIX), (2, GpsFixType.DGPS), (4, GpsFixType.RTK_FIXED)):
        assert dec.decode(gga("120001.00", LAT, LON, 5.0, quality), 1).fix_type == kind


def test_bad_checksums_truncation_and_garbage_are_counted():
    dec = NmeaGpsDecoder()
    good = gga("120000.00", LAT, LON, 10.0)
    broken = good[:-2] + ("00" if good[-2:] != "00" else "11")
    assert dec.decode(broken, 0) is None
    assert dec.decode(good[:20], 0) is None
    assert dec.decode(b"\xff\xfe$GPXYZ,1,2*00", 0) is None
    assert (
        dec.decode("$GPGSV,3,1,11,03,03,111,00,04,15,270,00,06,01,010,00,13,06,292,00*74", 0)
        is None
    )
    c = dec.counters
    assert (c.bad_checksum, c.ignored, c.garbage, c.ok) == (1, 1, 2, 0)


def test_framer_finds_sentences_in_junk_and_split_reads():
    framer = LineFramer()
    s1, s2 = gga("120000.00", LAT, LON, 1.0), gga("120001.00", LAT, LON, 2.0)
    stream = b"junk\x00" + s1.encode() + b"\r\n$GPG" + b"\r\n" + s2.encode() + b"\r\n"
    out = []
    for i in range(0, len(stream), 7):
        out += framer.feed(stream[i : i + 7])
    assert out[0] == s1.encode() and out[-1] == s2.encode()
    assert framer.counters.garbage_bytes >= 5


@given(st.binary(max_size=400))
def test_any_bytes_never_raise(data):
    framer, dec = LineFramer(), NmeaGpsDecoder()
    for line in framer.feed(data):
        dec.decode(line, 0)
