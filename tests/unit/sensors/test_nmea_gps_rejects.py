"""NMEA rejects: bad checksums, truncation, malformed fields and junk are counted, never raised."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from companion.sensors.nmea_gps import NmeaGpsDecoder
from tests.unit.sensors.nmea_text import GSV, gga, gsa, nmea, rmc, vtg

GOOD = [gga("120000.00"), rmc("120000.00"), vtg(), gsa()]


def counts(dec: NmeaGpsDecoder) -> tuple[int, int, int, int]:
    c = dec.counters
    return c.ok, c.bad_checksum, c.garbage, c.ignored


def with_checksum(sentence: str, checksum: str) -> str:
    return sentence[: sentence.index("*") + 1] + checksum


def test_a_wrong_checksum_is_counted_for_every_type():
    dec = NmeaGpsDecoder()
    for sentence in GOOD:
        wrong = "00" if not sentence.endswith("00") else "11"
        assert dec.decode(with_checksum(sentence, wrong), 0) is None
    assert dec.decode(GOOD[0].replace("123.4", "128.4"), 0) is None  # a flipped digit
    assert counts(dec) == (0, 5, 0, 0)


def test_every_truncation_is_counted_as_garbage():
    dec = NmeaGpsDecoder()
    sentence = GOOD[0]
    for cut in range(len(sentence)):
        assert dec.decode(sentence[:cut], 0) is None
    assert counts(dec) == (0, 0, len(sentence), 0)
    dec.decode(sentence.encode() + b"\r\n", 0)
    assert counts(dec) == (1, 0, len(sentence), 0), "bytes with a line ending are fine"


@pytest.mark.parametrize(
    "body",
    [
        "GPGGA,120000.00",  # checksummed, but the fields stop early
        "GPGGA,120000.00,3754.63,S,14508.04,E,1,09,0.9,,M,,M,,",  # a fix without altitude
        "GPGGA,120000.00,3761.00,S,14508.04,E,1,09,0.9,10,M,,M,,",  # 61 minutes
        "GPGGA,120000.00,9100.00,S,14508.04,E,1,09,0.9,10,M,,M,,",  # 91 degrees
        "GPGGA,120000.00,3754.63,X,14508.04,E,1,09,0.9,10,M,,M,,",  # no such hemisphere
        "GPGGA,120000.00,3754.63,S,14508.04,E,1,09,0.9,nan,M,,M,,",
        "GPGGA,120000.00,3754.63,S,14508.04,E,9,09,0.9,10,M,,M,,",  # quality 9
        "GPGGA,126000.00,3754.63,S,14508.04,E,1,09,0.9,10,M,,M,,",  # minute 60
        "GPGGA,120000.00,3754.63,S,14508.04,E,1,09,0.9,10,F,,M,,",  # feet
        "GPRMC,120000.00,X,3754.63,S,14508.04,E,1.0,0.0,231126,,",
        "GPRMC,120000.00,A,,,,,1.0,0.0,231126,,",  # valid but no position
        "GPRMC,120000.00,A,3754.63,S,14508.04,E,1.0,0.0,321126,,",  # 32nd day
        "GPRMC,120000.00,A,3754.63,S,14508.04,E,1.0,361.0,231126,,",
        "GPVTG,90.0,T,,M,-4.0,N,,K,A",
        "GPVTG,054.7,034.4,005.5,010.2",  # the pre-2.0 layout
        "GPGSA,A,4,04,05,,,,,,,,,,,1.7,0.9,1.4",
    ],
)
def test_checksummed_sentences_with_bad_fields_are_garbage(body):
    dec = NmeaGpsDecoder()
    assert dec.decode(nmea(body), 0) is None
    assert counts(dec) == (0, 0, 1, 0)


@pytest.mark.parametrize(
    "sentence",
    [GSV, nmea("GPGLL,3754.63,S,14508.04,E,120000.00,A,A"), nmea("PUBX,00,1"), nmea("GPXYZ,1")],
)
def test_valid_sentences_of_other_types_are_ignored(sentence):
    dec = NmeaGpsDecoder()
    assert dec.decode(sentence, 0) is None
    assert counts(dec) == (0, 0, 0, 1)


@pytest.mark.parametrize(
    "junk",
    [
        b"",
        b"\xff\xfe" + GOOD[0].encode(),
        GOOD[0][1:],  # no '$'
        GOOD[0][: GOOD[0].index("*")],  # no checksum at all
        with_checksum(GOOD[0], "ZZ"),
        with_checksum(GOOD[0], "6F6F"),
        "$",
        "$*00",
        "hello",
    ],
)
def test_junk_is_garbage(junk):
    dec = NmeaGpsDecoder()
    assert dec.decode(junk, 0) is None
    assert counts(dec) == (0, 0, 1, 0)


def _decoded_once_each(dec: NmeaGpsDecoder, calls: int) -> bool:
    return sum(counts(dec)) == calls


@given(st.lists(st.one_of(st.text(max_size=120), st.binary(max_size=120)), max_size=20))
def test_any_input_never_raises(inputs):
    dec = NmeaGpsDecoder()
    for item in inputs:
        dec.decode(item, 0)
    assert _decoded_once_each(dec, len(inputs))


_EPOCH = [rmc("120000.00"), vtg(), gga("120000.00"), gsa(), GSV]
_PRINTABLE = st.characters(min_codepoint=0x20, max_codepoint=0x7E)


@given(
    st.lists(
        st.tuples(st.sampled_from(_EPOCH), st.integers(0, 200), _PRINTABLE, st.booleans()),
        max_size=30,
    )
)
def test_mutated_sentences_never_raise_and_are_each_counted_once(edits):
    dec = NmeaGpsDecoder()
    for sentence, where, char, replace in edits:
        i = where % len(sentence)
        mutated = sentence[:i] + char + sentence[i + 1 if replace else i :]
        fix = dec.decode(mutated, 0)
        assert fix is None or fix.fix_type <= 6
    assert _decoded_once_each(dec, len(edits))


_FIELD = st.one_of(
    st.text(alphabet="0123456789.-+eE", max_size=12),
    st.text(alphabet=st.characters(min_codepoint=0x20, max_codepoint=0x7E), max_size=6).filter(
        lambda f: "*" not in f and "," not in f
    ),
)


@given(
    st.sampled_from(["GPGGA", "GNRMC", "GPVTG", "GNGSA"]),
    st.lists(_FIELD, max_size=16),
)
def test_checksummed_random_fields_never_raise(kind, fields):
    dec = NmeaGpsDecoder()
    for time in ("120000.00", "120001.00", "120002.00"):  # past the learning epoch
        dec.decode(gga(time), 0)
        dec.decode(nmea(",".join([kind, *fields])), 0)
    assert _decoded_once_each(dec, 6)
