"""NMEA sentences for the decoder's tests, checksummed here, not by the code under test.

The position is chosen so that minutes / 60 is an exact decimal: the expected degrees
below are the true values to the last digit, not a re-run of the decoder's arithmetic.
"""

from __future__ import annotations

import datetime as dt
from functools import reduce

from companion.messages import GpsFix
from companion.sensors.nmea_gps import NmeaGpsDecoder

LAT_TEXT, LAT = "3754.630738", -37.9105123  # S
LON_TEXT, LON = "14508.042736", 145.1340456  # E
KNOT = 0.514444444444  # m/s, to 12 digits


def nmea(body: str) -> str:
    """``$body*hh`` with the NMEA XOR checksum."""
    return f"${body}*{reduce(lambda acc, ch: acc ^ ord(ch), body, 0):02X}"


def gga(time: str, alt: float = 123.4, quality: int = 1, talker: str = "GP", **kw: str) -> str:
    lat, ns = kw.get("lat", LAT_TEXT), kw.get("ns", "S")
    sats, hdop = kw.get("sats", "09"), kw.get("hdop", "0.9")
    return nmea(
        f"{talker}GGA,{time},{lat},{ns},{LON_TEXT},E,{quality},{sats},{hdop},{alt},M,-1.5,M,,"
    )


def rmc(time: str, date: str = "231126", knots: str = "40.0", course: str = "90.0", **kw: str):
    talker, status = kw.get("talker", "GP"), kw.get("status", "A")
    return nmea(
        f"{talker}RMC,{time},{status},{LAT_TEXT},S,{LON_TEXT},E,{knots},{course},{date},11.5,E,A"
    )


def vtg(course: str = "90.0", knots: str = "40.0", kmh: str = "74.08", talker: str = "GP"):
    return nmea(f"{talker}VTG,{course},T,,M,{knots},N,{kmh},K,A")


def gsa(mode: int = 3, hdop: str = "0.9", vdop: str = "1.4", talker: str = "GP") -> str:
    return nmea(f"{talker}GSA,A,{mode},04,05,09,12,,,,,,,,,1.7,{hdop},{vdop}")


GSV = nmea("GPGSV,3,1,11,03,03,111,00,04,15,270,00,06,01,010,00,13,06,292,00")


def utc_us(*when: int) -> int:
    """µs since 1970 of a UTC date and time, by the standard library."""
    return int(dt.datetime(*when, tzinfo=dt.UTC).timestamp()) * 1_000_000


def decode_all(dec: NmeaGpsDecoder, timed: list[tuple[int, str]]) -> list[GpsFix]:
    """Feed (t_us, sentence) pairs; the fixes that came out, in order."""
    fixes = []
    for t_us, sentence in timed:
        fix = dec.decode(sentence, t_us)
        if fix is not None:
            fixes.append(fix)
    return fixes
