"""NMEA 0183 GPS sentences (GGA, RMC, VTG, GSA; any talker) into GPS fixes, via pynmea2.

Epoch rule: a fix is emitted on each GGA (position, altitude, quality), carrying the
newest RMC/VTG velocity and GSA dilution seen within the last 1.5 s, whichever order the
receiver sends them in. A receiver that sends no GGA at all (a second RMC arrives with no
GGA seen) gets a 2-D fix on each RMC from then on.
Vertical velocity comes from successive GGA altitudes over the REAL time between their
UTC stamps (midnight handled), and is unknown (NaN) on the first fix or after a gap > 5 s.
"""

from __future__ import annotations

import datetime as dt
import math
from dataclasses import dataclass

import pynmea2

from companion.messages import GpsFix, GpsFixType

KNOT_M_S = 0.514444
UERE_M = 2.5  # user-equivalent range error: eph ≈ UERE × HDOP
STALE_US = 1_500_000
MAX_VZ_GAP_S = 5.0


@dataclass
class NmeaCounters:
    ok: int = 0
    bad_checksum: int = 0
    garbage: int = 0
    ignored: int = 0  # valid sentences we do not use (GSV, ...)


def _seconds_of_day(stamp: dt.time | None) -> float | None:
    if stamp is None:
        return None
    return stamp.hour * 3600 + stamp.minute * 60 + stamp.second + stamp.microsecond / 1e6


def _num(value: object) -> float:
    try:
        return float(value) if value not in (None, "") else math.nan  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return math.nan


class NmeaGpsDecoder:
    """Stateful: remembers the epoch's pieces between sentences."""

    def __init__(self) -> None:
        self.counters = NmeaCounters()
        self.velocity: tuple[int, float, float] | None = None  # t_us, speed m/s, course deg
        self.dop: tuple[int, float, float, int] | None = None  # t_us, hdop, vdop, mode
        self.date: dt.date | None = None
        self.last_alt: tuple[float, float] | None = None  # seconds of day, altitude
        self.seen_gga = False
        self.rmc_epochs = 0  # RMCs seen: a second one with no GGA yet means an RMC-only receiver

    def decode(self, sentence: bytes | str, t_us: int) -> GpsFix | None:
        text = sentence.decode("ascii", "replace") if isinstance(sentence, bytes) else sentence
        if "*" not in text:  # cut off before its checksum: a truncated frame
            self.counters.garbage += 1
            return None
        try:
            msg = pynmea2.parse(text.strip(), check=True)
        except pynmea2.ChecksumError:
            self.counters.bad_checksum += 1
            return None
        except (pynmea2.ParseError, ValueError, TypeError, AttributeError):
            self.counters.garbage += 1
            return None
        handler = getattr(self, f"_on_{msg.sentence_type.lower()}", None)
        if handler is None:
            self.counters.ignored += 1
            return None
        try:
            fix = handler(msg, t_us)
        except (ValueError, TypeError, AttributeError):
            self.counters.garbage += 1
            return None
        self.counters.ok += 1
        return fix

    def _on_vtg(self, msg: pynmea2.VTG, t_us: int) -> None:
        knots = _num(msg.spd_over_grnd_kts)
        speed = knots * KNOT_M_S if math.isfinite(knots) else _num(msg.spd_over_grnd_kmph) / 3.6
        self.velocity = (t_us, speed, _num(msg.true_track))

    def _on_gsa(self, msg: pynmea2.GSA, t_us: int) -> None:
        mode = int(_num(msg.mode_fix_type)) if math.isfinite(_num(msg.mode_fix_type)) else 0
        self.dop = (t_us, _num(msg.hdop), _num(msg.vdop), mode)

    def _on_rmc(self, msg: pynmea2.RMC, t_us: int) -> GpsFix | None:
        if msg.datestamp:
            self.date = msg.datestamp
        self.velocity = (t_us, _num(msg.spd_over_grnd) * KNOT_M_S, _num(msg.true_course))
        rmc_only = self.rmc_epochs > 0 and not self.seen_gga
        self.rmc_epochs += 1
        if not rmc_only or msg.status != "A":
            return None
        fix = GpsFix(t_us=t_us, lat_deg=msg.latitude, lon_deg=msg.longitude)
        fix.alt_msl_m = math.nan
        fix.fix_type = GpsFixType.FIX_2D
        self._fill(fix, t_us, msg.timestamp, math.nan)
        return fix

    def _on_gga(self, msg: pynmea2.GGA, t_us: int) -> GpsFix:
        self.seen_gga = True
        quality = int(_num(msg.gps_qual)) if math.isfinite(_num(msg.gps_qual)) else 0
        fix = GpsFix(t_us=t_us, lat_deg=msg.latitude, lon_deg=msg.longitude)
        fix.alt_msl_m = _num(msg.altitude)
        fix.satellites = (
            min(254, int(_num(msg.num_sats))) if math.isfinite(_num(msg.num_sats)) else 255
        )
        fix.fix_type = self._fix_type(quality, t_us)
        self._fill(fix, t_us, msg.timestamp, _num(msg.horizontal_dil))
        return fix

    def _fix_type(self, quality: int, t_us: int) -> int:
        if quality == 0:
            return GpsFixType.NO_FIX
        if quality == 4:
            return GpsFixType.RTK_FIXED
        if quality == 5:
            return GpsFixType.RTK_FLOAT
        if quality == 2:
            return GpsFixType.DGPS
        if self.dop is not None and t_us - self.dop[0] < STALE_US and self.dop[3] == 2:
            return GpsFixType.FIX_2D
        return GpsFixType.FIX_3D

    def _fill(self, fix: GpsFix, t_us: int, stamp: dt.time | None, hdop: float) -> None:
        fix.hdop, fix.vdop = hdop, math.nan
        if self.dop is not None and t_us - self.dop[0] < STALE_US:
            fix.hdop = self.dop[1] if math.isfinite(self.dop[1]) else hdop
            fix.vdop = self.dop[2]
        fix.eph_m = UERE_M * fix.hdop
        fix.epv_m = UERE_M * fix.vdop
        fix.vn_m_s = fix.ve_m_s = fix.ground_speed_m_s = fix.course_rad = math.nan
        if self.velocity is not None and t_us - self.velocity[0] < STALE_US:
            _, speed, course = self.velocity
            fix.ground_speed_m_s = speed
            if math.isfinite(course):
                fix.course_rad = math.radians(course) % (2 * math.pi)
                fix.vn_m_s = speed * math.cos(fix.course_rad)
                fix.ve_m_s = speed * math.sin(fix.course_rad)
        fix.vd_m_s = self._vertical_speed(_seconds_of_day(stamp), fix.alt_msl_m)
        if stamp is not None and self.date is not None:
            when = dt.datetime.combine(self.date, stamp, tzinfo=dt.UTC)
            fix.utc_us = int(when.timestamp() * 1e6)

    def _vertical_speed(self, sod: float | None, alt: float) -> float:
        if sod is None or not math.isfinite(alt):
            return math.nan
        previous, self.last_alt = self.last_alt, (sod, alt)
        if previous is None:
            return math.nan
        gap = (sod - previous[0]) % 86400.0  # across midnight too
        if gap <= 0 or gap > MAX_VZ_GAP_S:
            return math.nan
        return -(alt - previous[1]) / gap
