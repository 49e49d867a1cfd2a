"""NMEA GPS epochs from several receivers: one fix per epoch, values to the last digit."""

from __future__ import annotations

import math

import pynmea2
import pytest

from companion.messages import GpsFixType
from companion.sensors.nmea_gps import NmeaGpsDecoder
from tests.unit.sensors.nmea_text import (
    GSV,
    KNOT,
    LAT,
    LAT_TEXT,
    LON,
    LON_TEXT,
    decode_all,
    gga,
    gsa,
    nmea,
    rmc,
    utc_us,
    vtg,
)


def ublox_epoch(second: int, alt: float, talker: str = "GN") -> list[tuple[int, str]]:
    """u-blox order: RMC, VTG, GGA, GSA per constellation, GSV, GLL; 50 ms apart."""
    time, t0 = f"1200{second:02d}.00", second * 1_000_000
    sentences = [
        rmc(time, talker=talker),
        vtg(talker=talker),
        gga(time, alt, talker=talker),
        gsa(3, "0.9", "1.4", talker),
        gsa(3, "0.9", "1.4", talker),
        GSV,
        nmea(f"{talker}GLL,{LAT_TEXT},S,{LON_TEXT},E,{time},A,A"),
    ]
    return [(t0 + 50_000 * (i + 1), s) for i, s in enumerate(sentences)]


def sirf_epoch(second: int, alt: float) -> list[tuple[int, str]]:
    """SiRF order: GGA, GSA, GSV, RMC, VTG; rendered by pynmea2 this time."""
    time, t0 = f"1200{second:02d}.000", second * 1_000_000
    fields = (time, LAT_TEXT, "S", LON_TEXT, "E", "1", "07", "1.1", f"{alt}", "M", "", "M", "", "")
    sentences = [
        str(pynmea2.GGA("GP", "GGA", fields)),
        gsa(3, "1.1", "2.0"),
        GSV,
        str(
            pynmea2.RMC(
                "GP",
                "RMC",
                (time, "A", LAT_TEXT, "S", LON_TEXT, "E", "10.0", "0.0", "231126", "", ""),
            )
        ),
        vtg("0.0", "10.0", "18.52"),
    ]
    return [(t0 + 50_000 * (i + 1), s) for i, s in enumerate(sentences)]


@pytest.mark.parametrize("talker", ["GP", "GN"])
def test_rmc_first_receiver_gets_a_fix_on_each_gga(talker):
    dec = NmeaGpsDecoder()
    first = [dec.decode(s, t) for t, s in ublox_epoch(0, 100.0, talker)]
    assert first[2] is not None and first[2].t_us == 50_000, "on the first epoch's GGA"
    assert math.isnan(first[2].vdop), "its GSA comes after it"
    assert len(decode_all(dec, ublox_epoch(1, 100.5, talker))) == 1
    fixes = decode_all(dec, ublox_epoch(2, 101.5, talker))
    assert len(fixes) == 1
    fix = fixes[0]
    assert fix.t_us == 2_050_000, "stamped with the epoch's first sentence (its RMC)"
    assert fix.lat_deg == pytest.approx(LAT, abs=1e-9)
    assert fix.lon_deg == pytest.approx(LON, abs=1e-9)
    assert fix.alt_msl_m == 101.5 and fix.fix_type == GpsFixType.FIX_3D
    assert fix.satellites == 9 and fix.hdop == 0.9 and fix.vdop == 1.4
    assert fix.eph_m == pytest.approx(2.25) and fix.epv_m == pytest.approx(3.5)
    assert fix.ground_speed_m_s == pytest.approx(40 * KNOT, abs=1e-9)
    assert fix.course_rad == pytest.approx(math.pi / 2)
    assert fix.ve_m_s == pytest.approx(40 * KNOT, abs=1e-9) and abs(fix.vn_m_s) < 1e-9
    assert fix.vd_m_s == pytest.approx(-1.0)
    assert fix.utc_us == utc_us(2026, 11, 23, 12, 0, 2)
    assert dec.counters.ok == 3 * 5 and dec.counters.ignored == 3 * 2
    assert dec.counters.fixes == 3 and dec.counters.dropped_epochs == 0


def test_gga_first_receiver_gets_its_fix_once_the_velocity_arrived():
    dec = NmeaGpsDecoder()
    first = [dec.decode(s, t) for t, s in sirf_epoch(0, 50.0)]
    assert [f is not None for f in first] == [False, False, False, True, False], (
        "the first epoch's on its RMC: a position and a velocity, the order not known yet"
    )
    timed = sirf_epoch(1, 48.0)
    fixes = [dec.decode(s, t) for t, s in timed]
    assert fixes[:-1] == [None] * 4 and fixes[-1] is not None, "emitted on the epoch's VTG"
    fix = fixes[-1]
    assert fix.t_us == 1_050_000, "stamped with the epoch's first sentence (its GGA)"
    assert fix.lat_deg == pytest.approx(LAT, abs=1e-9)
    assert fix.lon_deg == pytest.approx(LON, abs=1e-9)
    assert fix.vn_m_s == pytest.approx(10 * KNOT, abs=1e-9) and fix.ve_m_s == 0.0
    assert fix.vd_m_s == pytest.approx(2.0) and fix.vdop == 2.0 and fix.satellites == 7
    assert fix.utc_us == utc_us(2026, 11, 23, 12, 0, 1)


def test_an_epoch_joined_after_its_gga_gives_no_2d_fix_of_a_3d_receiver():
    """Started (or restarted) half-way through a SiRF epoch: its RMC alone is no fix."""
    dec = NmeaGpsDecoder()
    timed = sirf_epoch(0, 50.0)[1:] + sirf_epoch(1, 48.0) + sirf_epoch(2, 47.0)
    fixes = decode_all(dec, timed)
    assert [f.t_us for f in fixes] == [1_050_000, 2_050_000]
    assert all(f.fix_type == GpsFixType.FIX_3D for f in fixes)


def test_a_gga_only_receiver_gets_a_fix_on_each_gga_from_the_second_and_drops_nothing():
    dec = NmeaGpsDecoder()
    fixes = decode_all(dec, [(i, gga(f"1200{i:02d}.00", 100.0 + i)) for i in range(4)])
    assert [f.t_us for f in fixes] == [1, 2, 3]
    assert all(math.isnan(f.vn_m_s) for f in fixes), "NMEA's GGA has no velocity"
    assert dec.counters.fixes == 3 and dec.counters.dropped_epochs == 0


def test_gga_and_vtg_only_receiver_takes_velocity_from_vtg_in_kmh():
    dec = NmeaGpsDecoder()
    timed = []
    for second in range(3):  # VTG first, knots field left empty
        timed += [(second, vtg("180.0", "", "36.0")), (second, gga(f"0000{second:02d}.00"))]
    fixes = decode_all(dec, timed)
    assert len(fixes) == 3  # the first epoch's when the second begins
    assert fixes[-1].vn_m_s == pytest.approx(-10.0) and abs(fixes[-1].ve_m_s) < 1e-9
    assert fixes[-1].course_rad == pytest.approx(math.pi)
    assert fixes[-1].utc_us == 0, "no RMC, no date"
    assert fixes[-1].fix_type == GpsFixType.FIX_3D, "GGA-only receivers: 3-D"


def test_rmc_only_receiver_gets_2d_fixes_without_altitude():
    dec = NmeaGpsDecoder()
    fixes = decode_all(dec, [(i, rmc(f"1200{i:02d}.00", knots="0.0", course="")) for i in range(3)])
    assert len(fixes) == 2
    fix = fixes[-1]
    assert fix.fix_type == GpsFixType.FIX_2D and math.isnan(fix.alt_msl_m)
    assert fix.lat_deg == pytest.approx(LAT, abs=1e-9)
    assert fix.vn_m_s == 0.0 and fix.ve_m_s == 0.0 and math.isnan(fix.course_rad)
    assert fix.satellites == 255 and math.isnan(fix.hdop)


@pytest.mark.parametrize(
    ("quality", "mode", "expected"),
    [
        (0, 1, GpsFixType.NO_FIX),
        (1, 2, GpsFixType.FIX_2D),
        (1, 3, GpsFixType.FIX_3D),
        (2, 3, GpsFixType.DGPS),
        (4, 3, GpsFixType.RTK_FIXED),
        (5, 3, GpsFixType.RTK_FLOAT),
        (6, 3, GpsFixType.NO_FIX),
        (1, 1, GpsFixType.NO_FIX),
    ],
)
def test_fix_type_comes_from_gga_quality_and_gsa_mode(quality, mode, expected):
    dec = NmeaGpsDecoder()
    timed = [(0, gga("120000.00")), (1, gsa(mode)), (2, gga("120001.00", quality=quality))]
    (fix,) = decode_all(dec, timed)
    assert fix.fix_type == expected


@pytest.mark.parametrize(
    ("quality", "metres_per_hdop"),
    [(1, 2.5), (2, 2.5), (5, 0.3), (4, 0.02)],
    ids=["gps", "dgps", "rtk-float", "rtk-fixed"],
)
def test_an_rtk_fix_claims_its_carrier_phase_accuracy(quality, metres_per_hdop):
    """An RTK receiver's HDOP is its satellites' geometry alone: the fix's accuracy is
    centimetres once its ambiguities are fixed, not the 2 m a consumer receiver's would be."""
    dec = NmeaGpsDecoder()
    timed = [(0, gga("120000.00")), (1, gsa(3, "0.6", "1.2"))]
    timed.append((2, gga("120001.00", quality=quality, hdop="0.6")))
    (fix,) = decode_all(dec, timed)
    assert fix.eph_m == pytest.approx(metres_per_hdop * 0.6)
    assert fix.epv_m == pytest.approx(metres_per_hdop * 1.2)


def test_no_fix_gga_without_position_gives_a_no_fix_message():
    dec = NmeaGpsDecoder()
    empty = nmea("GPGGA,120001.00,,,,,0,00,99.99,,,,,,")
    (fix,) = decode_all(dec, [(0, gga("120000.00")), (1, empty)])
    assert fix.fix_type == GpsFixType.NO_FIX and math.isnan(fix.lat_deg)
    assert fix.satellites == 0 and fix.hdop == 99.99


def test_an_epoch_missing_its_rmc_comes_one_epoch_late_and_one_missing_gga_is_dropped():
    dec = NmeaGpsDecoder()
    decode_all(dec, ublox_epoch(0, 100.0) + ublox_epoch(1, 100.0))
    no_rmc = ublox_epoch(2, 100.0)[1:]  # its RMC lost to a bad checksum
    assert decode_all(dec, no_rmc) == []
    late, on_time = decode_all(dec, ublox_epoch(3, 100.0))
    assert late.t_us == 2_100_000 and late.utc_us == utc_us(2026, 11, 23, 12, 0, 2)
    assert late.ve_m_s == pytest.approx(40 * KNOT, abs=1e-9), "velocity from the VTG"
    assert on_time.t_us == 3_050_000
    no_gga = [pair for pair in ublox_epoch(4, 100.0) if "GGA" not in pair[1]]
    assert decode_all(dec, no_gga + ublox_epoch(5, 100.0)[:1]) == []
    assert dec.counters.dropped_epochs == 1


def test_a_receiver_that_stops_sending_rmc_is_followed_after_three_epochs():
    dec = NmeaGpsDecoder()
    timed = []
    for second in range(3):
        timed += [(second, rmc(f"1200{second:02d}.00")), (second, gga(f"1200{second:02d}.00"))]
    for second in range(3, 9):  # from here on, GGA only
        timed.append((second, gga(f"1200{second:02d}.00")))
    fixes = decode_all(dec, timed)
    # Epochs 3-5 wait for an RMC and come late; at 6 RMC is forgotten: epoch 5's late fix
    # and epoch 6's on-time fix fall due together, and only the newer one is kept.
    assert [f.t_us for f in fixes] == [0, 1, 2, 3, 4, 6, 7, 8]
    assert dec.counters.fixes == len(fixes) and dec.counters.dropped_epochs == 1
