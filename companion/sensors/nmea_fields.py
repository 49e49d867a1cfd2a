"""Typed, validated field values of the NMEA sentences a GPS fix is built from.

pynmea2 finds the sentence type, checks the checksum and splits the fields; it returns a
field's raw text when its own conversion fails (and happily converts ``nan``), so every
value is re-checked here: each function raises ValueError on a malformed field and the
decoder counts that as garbage. Units are converted on the way out (knots → m/s).
"""

from __future__ import annotations

import datetime as dt
import math
import re
from dataclasses import dataclass

import pynmea2
from pynmea2.nmea_utils import datestamp, dm_to_sd

KNOT_M_S = 1852.0 / 3600.0  # exact: an international knot is one nautical mile an hour
_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)")
_TIME = re.compile(r"(\d\d)(\d\d)(\d\d)(?:\.(\d{1,6}))?")
_GGA_QUALITIES = range(9)  # 0 none … 6 dead reckoning, 7 manual, 8 simulator


@dataclass(frozen=True)
class GgaData:
    """Position, altitude and quality of one GGA."""

    tod_us: int | None  # UTC time of day of the fix, µs
    lat_deg: float  # NaN when the sentence carries no position
    lon_deg: float
    alt_msl_m: float
    quality: int
    satellites: int | None
    hdop: float


@dataclass(frozen=True)
class RmcData:
    """Position, velocity and date of one RMC."""

    tod_us: int | None
    valid: bool  # status A and a mode indicator other than N
    lat_deg: float
    lon_deg: float
    speed_m_s: float
    course_deg: float  # true, NaN when not given
    date: dt.date | None


@dataclass(frozen=True)
class VtgData:
    """Velocity over ground of one VTG."""

    valid: bool
    speed_m_s: float
    course_deg: float


@dataclass(frozen=True)
class GsaData:
    """Fix mode and dilutions of precision of one GSA."""

    mode: int | None  # 1 no fix, 2 2-D, 3 3-D
    hdop: float
    vdop: float


def field(msg: pynmea2.TalkerSentence, name: str) -> str:
    """The raw text of a named field; '' when the sentence is too short to have it."""
    index = type(msg).name_to_idx[name]
    return msg.data[index].strip() if index < len(msg.data) else ""


def number(text: str) -> float:
    """A plain decimal number; NaN for an empty field; ValueError for anything else."""
    if not text:
        return math.nan
    if not _NUMBER.fullmatch(text):
        raise ValueError(f"not a number: {text!r}")
    return float(text)


def time_of_day_us(text: str) -> int | None:
    """``hhmmss[.ss]`` as µs since midnight UTC (a leap second 60 is allowed)."""
    if not text:
        return None
    match = _TIME.fullmatch(text)
    if not match:
        raise ValueError(f"not a UTC time: {text!r}")
    hours, minutes, seconds = (int(g) for g in match.groups()[:3])
    if hours > 23 or minutes > 59 or seconds > 60:
        raise ValueError(f"UTC time out of range: {text!r}")
    fraction = int((match.group(4) or "").ljust(6, "0"))
    return ((hours * 60 + minutes) * 60 + seconds) * 1_000_000 + fraction


def coordinate(value: str, hemisphere: str, positive: str, negative: str, limit: float) -> float:
    """``(d)ddmm.mmmm`` and its hemisphere letter as signed degrees; NaN when both are empty."""
    if not value and not hemisphere:
        return math.nan
    if hemisphere not in (positive, negative) or "." not in value:
        raise ValueError(f"bad coordinate {value!r} {hemisphere!r}")
    degrees = dm_to_sd(value)  # pynmea2's: strict ddmm.mmm pattern, ValueError otherwise
    minutes = float(value[value.index(".") - 2 :])
    if minutes >= 60 or degrees > limit:
        raise ValueError(f"coordinate out of range: {value!r}")
    return -degrees if hemisphere == negative else degrees


def _position(msg: pynmea2.TalkerSentence) -> tuple[float, float]:
    lat = coordinate(field(msg, "lat"), field(msg, "lat_dir"), "N", "S", 90.0)
    lon = coordinate(field(msg, "lon"), field(msg, "lon_dir"), "E", "W", 180.0)
    if math.isnan(lat) != math.isnan(lon):
        raise ValueError("latitude without longitude or the reverse")
    return lat, lon


def _count(text: str) -> int | None:
    value = number(text)
    if math.isnan(value):
        return None
    if value != int(value) or value < 0:
        raise ValueError(f"not a count: {text!r}")
    return int(value)


def gga(msg: pynmea2.TalkerSentence) -> GgaData:
    """The fields of a GGA; a fix (quality > 0) must give position and altitude."""
    quality = _count(field(msg, "gps_qual"))
    if quality is None or quality not in _GGA_QUALITIES:
        raise ValueError("GGA without a valid quality indicator")
    lat, lon = _position(msg)
    alt = number(field(msg, "altitude"))
    if field(msg, "altitude_units") not in ("", "M"):
        raise ValueError("GGA altitude not in metres")
    if quality > 0 and (math.isnan(lat) or math.isnan(alt)):
        raise ValueError("GGA fix without position or altitude")
    hdop = number(field(msg, "horizontal_dil"))
    return GgaData(
        time_of_day_us(field(msg, "timestamp")),
        lat,
        lon,
        alt,
        quality,
        _count(field(msg, "num_sats")),
        hdop,
    )


def _course(text: str) -> float:
    course = number(text)
    if not math.isnan(course) and not 0.0 <= course <= 360.0:
        raise ValueError(f"course out of range: {text!r}")
    return course


def rmc(msg: pynmea2.TalkerSentence) -> RmcData:
    """The fields of an RMC; a valid one must give a position."""
    status = field(msg, "status")
    if status not in ("A", "V"):
        raise ValueError(f"RMC status {status!r}")
    valid = status == "A" and field(msg, "mode_indicator") != "N"
    lat, lon = _position(msg)
    if valid and math.isnan(lat):
        raise ValueError("valid RMC without a position")
    speed = number(field(msg, "spd_over_grnd"))
    if speed < 0:
        raise ValueError("negative speed")
    date_text = field(msg, "datestamp")
    return RmcData(
        time_of_day_us(field(msg, "timestamp")),
        valid,
        lat,
        lon,
        speed * KNOT_M_S,
        _course(field(msg, "true_course")),
        datestamp(date_text) if date_text else None,
    )


def vtg(msg: pynmea2.TalkerSentence) -> VtgData:
    """The fields of a VTG (NMEA 2.3+ layout with unit letters); knots preferred over km/h."""
    for name, letter in (("true_track_sym", "T"), ("spd_over_grnd_kts_sym", "N")):
        if field(msg, name) not in ("", letter):
            raise ValueError("VTG fields out of place")
    knots = number(field(msg, "spd_over_grnd_kts"))
    kmph = number(field(msg, "spd_over_grnd_kmph"))
    speed = knots * KNOT_M_S if not math.isnan(knots) else kmph / 3.6
    if speed < 0:
        raise ValueError("negative speed")
    valid = field(msg, "faa_mode") != "N" and not math.isnan(speed)
    return VtgData(valid, speed, _course(field(msg, "true_track")))


def gsa(msg: pynmea2.TalkerSentence) -> GsaData:
    """The fix mode and dilutions of a GSA."""
    mode = _count(field(msg, "mode_fix_type"))
    if mode is not None and mode not in (1, 2, 3):
        raise ValueError(f"GSA mode {mode}")
    hdop, vdop = number(field(msg, "hdop")), number(field(msg, "vdop"))
    return GsaData(mode, hdop, vdop)
