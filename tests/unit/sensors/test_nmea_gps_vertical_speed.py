"""Vertical speed from successive GGA altitudes over the real time between their UTC stamps."""

from __future__ import annotations

import math

import pytest

from companion.sensors.nmea_gps import NmeaGpsDecoder
from tests.unit.sensors.nmea_text import decode_all, gga, rmc, utc_us


def gga_only(*epochs: tuple[str, float]) -> list[float]:
    """vd of each fix of a GGA-only receiver; every sentence arrives at the same t_us, so
    only the UTC stamps can give the interval."""
    dec = NmeaGpsDecoder()
    return [fix.vd_m_s for fix in decode_all(dec, [(0, gga(t, alt)) for t, alt in epochs])]


def test_over_a_fifth_of_a_second():
    vd = gga_only(("120000.00", 100.0), ("120000.20", 101.0), ("120000.40", 101.5))
    assert vd == [pytest.approx(-5.0), pytest.approx(-2.5)]


def test_over_one_second_and_descending_is_positive():
    vd = gga_only(("120000.0", 100.0), ("120001.0", 99.0), ("120002.0", 96.5))
    assert vd == [pytest.approx(1.0), pytest.approx(2.5)]


def test_across_midnight_and_the_date_rolls_over():
    dec = NmeaGpsDecoder()
    timed = [
        (0, rmc("235959.60", "231126")),
        (0, gga("235959.60", 200.0)),
        (1, rmc("235959.80", "231126")),
        (1, gga("235959.80", 200.0)),
        (2, gga("000000.00", 201.0)),  # the RMCs of these two epochs lost:
        (3, gga("000000.20", 202.0)),  # the date still rolls over at midnight
        (4, rmc("000000.40", "241126")),
    ]
    first, *fixes = decode_all(dec, timed)
    assert math.isnan(first.vd_m_s), "the first altitude has none before it"
    assert [f.vd_m_s for f in fixes] == [0.0, pytest.approx(-5.0), pytest.approx(-5.0)]
    assert fixes[1].utc_us == utc_us(2026, 11, 24, 0, 0, 0)
    assert fixes[2].utc_us == utc_us(2026, 11, 24, 0, 0, 0) + 200_000


def test_unknown_after_a_gap_over_five_seconds_or_a_step_back_in_time():
    vd = gga_only(
        ("120000.00", 100.0),
        ("120001.00", 100.0),
        ("120006.50", 110.0),  # 5.5 s gap
        ("120007.50", 111.0),
        ("120007.00", 112.0),  # time went backwards
    )
    assert vd[0] == 0.0 and math.isnan(vd[1]) and vd[2] == pytest.approx(-1.0)
    assert math.isnan(vd[3])


def test_a_no_fix_epoch_in_between_does_not_reset_the_reference():
    no_fix = gga("120001.00", 0.0, quality=0)
    dec = NmeaGpsDecoder()
    timed = [(0, gga("120000.00", 100.0)), (0, no_fix), (0, gga("120002.00", 98.0))]
    fixes = decode_all(dec, timed)
    assert math.isnan(fixes[0].vd_m_s) and fixes[1].vd_m_s == pytest.approx(1.0)
