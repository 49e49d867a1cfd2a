"""The recorded sensor log (CSV) of the design: read it into bus messages.

Header ``t,kind,ax,ay,az,gx,gy,gz,lat,lon,alt_m,vn,ve,vd,fix,hdop,mx,my,mz,baro_alt_m,
heading_deg,pitch_deg,roll_deg`` and optionally ``vd_std`` (which ``companion log`` adds);
columns are found by name and absent ones are empty (older files stop at ``baro_alt_m``).
A row that cannot be read is counted and skipped with a warning naming its line; it never
stops the reading.
"""

from __future__ import annotations

import csv
import logging
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from companion.messages import Baro, Compass, GpsFix, Imu, Magnetometer, Message

log = logging.getLogger(__name__)
KINDS = ("imu", "gps", "mag", "baro", "compass")


@dataclass
class LogStats:
    """What reading a log found."""

    rows: int = 0
    bad: int = 0
    by_kind: dict[str, int] = field(default_factory=dict)


def _f(row: dict[str, str], key: str) -> float:
    text = (row.get(key) or "").strip()
    return float(text) if text else math.nan


def _required(row: dict[str, str], keys: tuple[str, ...], kind: str) -> list[float]:
    """The row's values for ``keys``, all present and finite (the common, fast case)."""
    try:
        values = [float(row[k]) for k in keys]
    except (KeyError, TypeError, ValueError):
        values = [math.nan]
    if not math.isfinite(sum(values)):
        raise ValueError(f"{kind} row needs {', '.join(keys)}")
    return values


_IMU_KEYS = ("ax", "ay", "az", "gx", "gy", "gz")
_MAG_KEYS = ("mx", "my", "mz")
_COMPASS_KEYS = ("heading_deg", "pitch_deg", "roll_deg")


def _imu(row: dict[str, str], t_us: int) -> Imu:
    return Imu(t_us, *_required(row, _IMU_KEYS, "imu"), math.nan)


def _gps(row: dict[str, str], t_us: int) -> GpsFix:
    """A fix, or a receiver's sample without one (``fix`` 0 or 1: its position may be
    empty, as a driver publishes it; the navigators skip it). A fix needs a position."""
    lat, lon, fix = _f(row, "lat"), _f(row, "lon"), _f(row, "fix")
    fix_type = 3 if math.isnan(fix) else max(0, min(6, round(fix)))
    has_fix = fix_type >= 2
    if (has_fix and (math.isnan(lat) or math.isnan(lon))) or abs(lat) > 90 or abs(lon) > 180:
        raise ValueError("gps row needs lat in [-90, 90] and lon in [-180, 180]")
    vn, ve = _f(row, "vn"), _f(row, "ve")
    msg = GpsFix(t_us=t_us, lat_deg=lat, lon_deg=lon, alt_msl_m=_f(row, "alt_m"))
    msg.vn_m_s, msg.ve_m_s, msg.vd_m_s = vn, ve, _f(row, "vd")
    vd_std = _f(row, "vd_std")  # the receiver's 1-sigma of vd; empty or absent: unknown
    msg.vd_std_m_s = vd_std if math.isfinite(vd_std) and vd_std > 0 else math.nan
    msg.ground_speed_m_s = math.hypot(vn, ve)
    msg.course_rad = math.atan2(ve, vn) % (2 * math.pi) if msg.ground_speed_m_s > 0.5 else math.nan
    msg.hdop, msg.vdop = _f(row, "hdop"), math.nan
    msg.eph_m = msg.hdop * 2.5 if not math.isnan(msg.hdop) else math.nan  # UERE-style estimate
    msg.epv_m = math.nan
    msg.fix_type = fix_type
    msg.satellites = 255
    return msg


def _mag(row: dict[str, str], t_us: int) -> Magnetometer:
    return Magnetometer(t_us, *_required(row, _MAG_KEYS, "mag"))


def _baro(row: dict[str, str], t_us: int) -> Baro:
    alt = _f(row, "baro_alt_m")
    if math.isnan(alt):
        raise ValueError("baro row needs baro_alt_m")
    return Baro(t_us, alt, math.nan)


def _compass(row: dict[str, str], t_us: int) -> Compass:
    values = _required(row, _COMPASS_KEYS, "compass")
    heading, pitch, roll = (math.radians(v) for v in values)
    return Compass(t_us, heading % (2 * math.pi), pitch, roll, math.nan)


PARSERS: dict[str, Callable[[dict[str, str], int], Message]] = {
    "imu": _imu,
    "gps": _gps,
    "mag": _mag,
    "baro": _baro,
    "compass": _compass,
}


def read_sensor_log(path: str | Path, stats: LogStats | None = None) -> Iterator[Message]:
    """The log's samples in file order, as bus messages with ``t_us`` from ``t``."""
    stats = stats if stats is not None else LogStats()
    with Path(path).open(newline="") as handle:
        reader = csv.DictReader(handle)
        if reader.fieldnames is None or "t" not in reader.fieldnames:
            raise ValueError(f"{path}: not a sensor log (no 't' column in the header)")
        for row in reader:
            stats.rows += 1
            kind = (row.get("kind") or "").strip()
            try:
                t_us = round(float(row["t"]) * 1e6)
                msg = PARSERS[kind](row, t_us)
            except (KeyError, ValueError, TypeError) as exc:
                stats.bad += 1
                reason = f"unknown kind {kind!r}" if kind not in PARSERS else str(exc)
                log.warning("%s:%d: skipped: %s", path, reader.line_num, reason)
                continue
            stats.by_kind[kind] = stats.by_kind.get(kind, 0) + 1
            yield msg


CHANNEL_OF = {
    Imu: "sensors/imu",
    GpsFix: "sensors/gps",
    Magnetometer: "sensors/mag",
    Baro: "sensors/baro",
    Compass: "sensors/compass",
}
