"""NMEA 0183 GPS sentences (GGA, RMC, VTG, GSA; any talker) into one GpsFix per epoch.

pynmea2 checks the checksum, finds the type and splits the fields; ``nmea_fields``
validates them. Pure: the caller passes each sentence with its reception time ``t_us``.

**Epoch rule.** Receivers send an epoch's sentences in their own order (u-blox: RMC, VTG,
GGA, GSA; SiRF: GGA, GSA, RMC, VTG), so the decoder learns the order instead of assuming
one:
- GGA and RMC carry the epoch's UTC time; a time different from the current epoch's, or a
  second sentence of a type the epoch already holds, begins a new epoch. VTG has no time:
  it joins the current epoch unless that epoch was already emitted, in which case it
  opens the next one.
- When an epoch ends, the decoder notes which of GGA, RMC and VTG it held. A type is
  *expected* until it has been missing from 3 epochs in a row.
- An epoch is emitted as soon as it holds every expected type; for u-blox that is on its
  GGA, for SiRF on its VTG. The first epoch teaches the order; its fix comes as soon as
  it holds a GGA and a velocity (RMC or VTG), or else, if it has a GGA, when it ends. So a
  started or restarted plug-in has a fix from the first epoch it hears.
- An epoch that ends incomplete (a sentence lost to a bad checksum) is emitted then, one
  epoch late, if it has a GGA; otherwise it is dropped and counted. A fix needs a GGA, or
  an RMC when the receiver sends no GGA at all (then it is 2-D, without altitude).
  ``decode`` returns at most one fix: should a late fix and an on-time one fall due on the
  same sentence (only when the receiver changes what it sends), the late one is dropped.
- GSA is not part of an epoch (multi-constellation receivers send one per system, and
  u-blox sends it after GGA): the newest GSA of this or the previous epoch is used.
- A fix's ``t_us`` is the reception time of its epoch's first sentence, the one nearest
  the measurement (at 4800 baud an epoch takes a few hundred ms to arrive).

Other values: fix type from GGA quality and GSA mode; HDOP from GGA (else GSA), VDOP from
GSA; ``eph_m``/``epv_m`` = UERE × HDOP/VDOP (UERE 2.5 m by default, as ``sensorlog`` uses);
NED velocity from RMC speed and course (else VTG); vertical velocity from successive GGA
altitudes over the real time between their UTC stamps (midnight handled), NaN on the first
fix or after a gap over 5 s; ``utc_us`` from RMC date and the epoch time.
"""

from __future__ import annotations

import datetime as dt
import logging
import math
from collections.abc import Callable
from dataclasses import dataclass

import pynmea2

from companion.messages import GpsFix, GpsFixType
from companion.sensors import nmea_fields
from companion.sensors.nmea_fields import GgaData, GsaData, RmcData, VtgData

log = logging.getLogger(__name__)
UERE_M = 2.5  # user-equivalent range error, 1 σ: eph ≈ UERE × HDOP
# With RTK corrections the range error is the carrier phase's: centimetres once the
# ambiguities are fixed, decimetres while they float (u-blox ZED-F9P: 1 cm + 1 ppm CEP).
RTK_UERE_M = {GpsFixType.RTK_FIXED: 0.02, GpsFixType.RTK_FLOAT: 0.3}
MAX_VZ_GAP_S = 5.0
MISSES_TO_FORGET = 3
_DAY_US = 86_400_000_000
_UNIX_DAY0 = dt.date(1970, 1, 1).toordinal()
_TAU = 2.0 * math.pi
_Fields = GgaData | RmcData | VtgData | GsaData
_EXTRACT: dict[str, Callable[[pynmea2.TalkerSentence], _Fields]] = {
    "GGA": nmea_fields.gga,
    "RMC": nmea_fields.rmc,
    "VTG": nmea_fields.vtg,
    "GSA": nmea_fields.gsa,
}
# What a malformed but checksummed sentence can make pynmea2 or our field checks raise.
_MALFORMED = (ValueError, IndexError, KeyError, TypeError, AttributeError)


DERIVED_VD_STD_M_S = 1.5


@dataclass
class NmeaCounters:
    """What the decoder has seen since it was made."""

    ok: int = 0  # GGA, RMC, VTG, GSA accepted
    bad_checksum: int = 0
    garbage: int = 0  # unparseable, truncated, or fields out of range
    ignored: int = 0  # valid sentences of other types (GSV, GLL, proprietary …)
    fixes: int = 0  # GpsFix messages emitted
    dropped_epochs: int = 0  # epochs that ended without enough for a fix


@dataclass
class _Epoch:
    t_us: int  # reception time of its first sentence
    index: int
    tod_us: int | None = None
    gga: GgaData | None = None
    rmc: RmcData | None = None
    vtg: VtgData | None = None
    vd_m_s: float = math.nan
    emitted: bool = False

    def kinds(self) -> set[str]:
        pairs = (("GGA", self.gga), ("RMC", self.rmc), ("VTG", self.vtg))
        return {kind for kind, data in pairs if data is not None}


class NmeaGpsDecoder:
    """Stateful: assembles epochs across sentences. ``decode`` never raises."""

    def __init__(self, uere_m: float = UERE_M, max_vz_gap_s: float = MAX_VZ_GAP_S) -> None:
        self.uere_m = uere_m
        self.max_vz_gap_s = max_vz_gap_s
        self.counters = NmeaCounters()
        self._epoch: _Epoch | None = None
        self._epochs = 0  # epochs begun
        self._misses: dict[str, int] = {}  # type → epochs in a row that ended without it
        self._learned = False
        self._gsa: GsaData | None = None
        self._gsa_epoch = -2  # index of the epoch during which the GSA arrived
        self._last_alt: tuple[int, float] | None = None  # time of day µs, altitude
        self._date: tuple[dt.date, int] | None = None  # newest RMC date, its time of day

    def decode(self, sentence: bytes | str, t_us: int) -> GpsFix | None:
        """Take one sentence; return a fix when it completes an epoch."""
        msg = self._parse(sentence)
        if msg is None:
            return None
        kind = msg.sentence_type
        extract = _EXTRACT.get(kind)
        if extract is None:
            self.counters.ignored += 1
            return None
        try:
            data = extract(msg)
        except _MALFORMED as exc:
            self.counters.garbage += 1
            log.debug("malformed %s: %s", kind, exc)
            return None
        self.counters.ok += 1
        if isinstance(data, GsaData):
            self._gsa, self._gsa_epoch = data, self._epochs
            return None
        return self._add(kind, data, t_us)

    def _parse(self, sentence: bytes | str) -> pynmea2.TalkerSentence | None:
        try:
            text = sentence.decode("ascii") if isinstance(sentence, bytes) else sentence
            text = text.strip("\r\n")
            if not text.startswith("$") or "*" not in text:  # truncated before its checksum
                raise pynmea2.ParseError("not a checksummed sentence", text)
            msg = pynmea2.parse(text, check=True)
        except pynmea2.ChecksumError:
            self.counters.bad_checksum += 1
            return None
        except pynmea2.SentenceTypeError:  # checksum was fine: a type pynmea2 does not know
            self.counters.ignored += 1
            return None
        except (pynmea2.ParseError, *_MALFORMED):
            self.counters.garbage += 1
            return None
        if not isinstance(msg, pynmea2.TalkerSentence):  # proprietary or query
            self.counters.ignored += 1
            return None
        return msg

    def _add(self, kind: str, data: GgaData | RmcData | VtgData, t_us: int) -> GpsFix | None:
        tod_us = getattr(data, "tod_us", None)
        late = None
        epoch = self._epoch
        if epoch is None or self._begins_epoch(epoch, kind, tod_us):
            if epoch is not None:
                late = self._close(epoch)
            self._epochs += 1
            epoch = self._epoch = _Epoch(t_us, self._epochs)
        if tod_us is not None:
            epoch.tod_us = tod_us
        if isinstance(data, GgaData):
            epoch.gga, epoch.vd_m_s = data, self._vertical_speed(data)
        elif isinstance(data, RmcData):
            epoch.rmc = data
            if data.date is not None and data.tod_us is not None:
                self._date = (data.date, data.tod_us)
        else:
            epoch.vtg = data
        if not epoch.emitted and self._complete(epoch):
            # Two fixes at once: the receiver changed its output, or (not counted) the first
            # epoch had no velocity and a GGA-only receiver's next one is due on its GGA.
            if late is not None and epoch.index > 2:
                self.counters.dropped_epochs += 1
            return self._emit(epoch)
        if late is not None:
            self.counters.fixes += 1
        return late

    def _begins_epoch(self, epoch: _Epoch, kind: str, tod_us: int | None) -> bool:
        if kind in epoch.kinds():
            return True
        if tod_us is None or epoch.tod_us is None:  # a VTG: the first epoch may still grow
            return epoch.emitted and self._learned
        return tod_us != epoch.tod_us

    def _expected(self) -> set[str]:
        return {kind for kind, misses in self._misses.items() if misses < MISSES_TO_FORGET}

    def _emittable(self, epoch: _Epoch) -> bool:
        return epoch.gga is not None or (epoch.rmc is not None and "GGA" not in self._expected())

    def _complete(self, epoch: _Epoch) -> bool:
        if not self._learned:  # the order unknown yet: a position and a velocity will do
            return epoch.gga is not None and (epoch.rmc is not None or epoch.vtg is not None)
        return self._expected() <= epoch.kinds() and self._emittable(epoch)

    def _close(self, epoch: _Epoch) -> GpsFix | None:
        """Learn from an ending epoch; its fix if it is still to be emitted (late), built
        now, before the next epoch's sentence changes what the decoder remembers."""
        late = None
        if not epoch.emitted and self._learned:
            if self._emittable(epoch):
                late, epoch.emitted = self._build(epoch), True
            else:
                self.counters.dropped_epochs += 1
        elif not epoch.emitted and epoch.gga is not None:
            # The first epoch without a velocity (joined half-way, or a GGA-only receiver):
            # late, as an incomplete one is. Without its GGA it may be a 3-D receiver's RMC
            # alone: no 2-D fix is made of that.
            late, epoch.emitted = self._build(epoch), True
        kinds = epoch.kinds()
        for kind in ("GGA", "RMC", "VTG"):
            if kind in kinds:
                self._misses[kind] = 0
            elif kind in self._misses:
                self._misses[kind] += 1
        self._learned = True
        return late

    def _emit(self, epoch: _Epoch) -> GpsFix:
        epoch.emitted = True
        self.counters.fixes += 1
        return self._build(epoch)

    def _vertical_speed(self, gga: GgaData) -> float:
        if gga.tod_us is None or gga.quality == 0 or math.isnan(gga.alt_msl_m):
            return math.nan
        previous, self._last_alt = self._last_alt, (gga.tod_us, gga.alt_msl_m)
        if previous is None:
            return math.nan
        gap_s = ((gga.tod_us - previous[0]) % _DAY_US) / 1e6  # across midnight too
        if not 0.0 < gap_s <= self.max_vz_gap_s:
            return math.nan
        return -(gga.alt_msl_m - previous[1]) / gap_s

    def _build(self, epoch: _Epoch) -> GpsFix:
        gga, rmc = epoch.gga, epoch.rmc
        gsa = self._gsa if self._gsa_epoch >= epoch.index - 1 else None
        fix = GpsFix(t_us=epoch.t_us, utc_us=self._utc_us(epoch))
        fix.lat_deg = fix.lon_deg = fix.alt_msl_m = math.nan
        if gga is not None and not math.isnan(gga.lat_deg):
            fix.lat_deg, fix.lon_deg, fix.alt_msl_m = gga.lat_deg, gga.lon_deg, gga.alt_msl_m
        elif rmc is not None and rmc.valid:
            fix.lat_deg, fix.lon_deg = rmc.lat_deg, rmc.lon_deg
        fix.fix_type = _fix_type(gga, rmc, gsa)
        fix.satellites = 255 if gga is None or gga.satellites is None else min(gga.satellites, 254)
        fix.hdop = gga.hdop if gga is not None and not math.isnan(gga.hdop) else math.nan
        if math.isnan(fix.hdop) and gsa is not None:
            fix.hdop = gsa.hdop
        fix.vdop = gsa.vdop if gsa is not None else math.nan
        uere = RTK_UERE_M.get(fix.fix_type, self.uere_m)
        fix.eph_m, fix.epv_m = uere * fix.hdop, uere * fix.vdop
        _set_velocity(fix, rmc, epoch.vtg)
        fix.vd_m_s = epoch.vd_m_s
        # NMEA has no vertical speed: this one differences two altitudes, each with metres
        # of noise, so say how rough it is.
        fix.vd_std_m_s = DERIVED_VD_STD_M_S if math.isfinite(epoch.vd_m_s) else math.nan
        return fix

    def _utc_us(self, epoch: _Epoch) -> int:
        if epoch.tod_us is None:
            return 0
        if epoch.rmc is not None and epoch.rmc.date is not None:
            day = epoch.rmc.date
        elif self._date is not None:
            day, rmc_tod = self._date
            if epoch.tod_us < rmc_tod:  # the clock passed midnight since that RMC
                day += dt.timedelta(days=1)
        else:
            return 0
        return (day.toordinal() - _UNIX_DAY0) * _DAY_US + epoch.tod_us


def _fix_type(gga: GgaData | None, rmc: RmcData | None, gsa: GsaData | None) -> GpsFixType:
    mode = gsa.mode if gsa is not None else None
    if gga is None:  # a receiver that sends no GGA: without altitude, 2-D at best
        valid = rmc is not None and rmc.valid and mode != 1
        return GpsFixType.FIX_2D if valid else GpsFixType.NO_FIX
    special = {2: GpsFixType.DGPS, 4: GpsFixType.RTK_FIXED, 5: GpsFixType.RTK_FLOAT}
    if gga.quality in special:
        return special[gga.quality]
    # 0 no fix, 6 dead reckoning, 7 manual input: no position from the satellites.
    if gga.quality in (0, 6, 7) or mode == 1:
        return GpsFixType.NO_FIX
    # 1 GPS, 3 PPS, 8 simulator: GSA tells 2-D from 3-D; a GGA-only receiver gives altitude.
    return GpsFixType.FIX_2D if mode == 2 else GpsFixType.FIX_3D


def _set_velocity(fix: GpsFix, rmc: RmcData | None, vtg: VtgData | None) -> None:
    speed = course = math.nan
    if rmc is not None and rmc.valid and not math.isnan(rmc.speed_m_s):
        speed, course = rmc.speed_m_s, rmc.course_deg
    elif vtg is not None and vtg.valid:
        speed, course = vtg.speed_m_s, vtg.course_deg
    fix.ground_speed_m_s = speed
    fix.course_rad = math.radians(course) % _TAU if not math.isnan(course) else math.nan
    if not math.isnan(fix.course_rad):
        fix.vn_m_s, fix.ve_m_s = speed * math.cos(fix.course_rad), speed * math.sin(fix.course_rad)
    elif speed == 0.0:  # standing still: receivers leave the course empty
        fix.vn_m_s = fix.ve_m_s = 0.0
    else:
        fix.vn_m_s = fix.ve_m_s = math.nan
