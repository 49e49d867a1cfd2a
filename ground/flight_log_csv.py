"""An on-board flight log (ULog) as the design's sensor log CSV, for ``companion replay``.

The sensor topics (``sensors_imu``, ``sensors_gps``, ``sensors_mag``, ``sensors_baro``,
``sensors_compass``) become rows of their kind in time order; values are written with
``repr`` so a float comes back to the same bits. Compass headings are written magnetic, as
the format has them: the declination the vehicle's navigator was set to (its compass
driver made them true with it) is taken off, and ``companion replay --declination`` with
that value puts it back (``replay_options`` says which options replay the CSV with the
settings the vehicle flew with).
"""

from __future__ import annotations

import csv
import heapq
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any, TextIO

from pyulog import ULog

from companion.navigation.sample_order import FEED_ORDER

HEADER = [
    "t",
    "kind",
    "ax",
    "ay",
    "az",
    "gx",
    "gy",
    "gz",
    "lat",
    "lon",
    "alt_m",
    "vn",
    "ve",
    "vd",
    "fix",
    "hdop",
    "mx",
    "my",
    "mz",
    "baro_alt_m",
    "heading_deg",
    "pitch_deg",
    "roll_deg",
    "vd_std",
]

# kind → topic, then CSV column → (ULog field, scale)
COLUMNS: dict[str, tuple[str, dict[str, tuple[str, float]]]] = {
    "imu": (
        "sensors_imu",
        {
            "ax": ("ax_m_s2", 1.0),
            "ay": ("ay_m_s2", 1.0),
            "az": ("az_m_s2", 1.0),
            "gx": ("gx_rad_s", 1.0),
            "gy": ("gy_rad_s", 1.0),
            "gz": ("gz_rad_s", 1.0),
        },
    ),
    "gps": (
        "sensors_gps",
        {
            "lat": ("lat_deg", 1.0),
            "lon": ("lon_deg", 1.0),
            "alt_m": ("alt_msl_m", 1.0),
            "vn": ("vn_m_s", 1.0),
            "ve": ("ve_m_s", 1.0),
            "vd": ("vd_m_s", 1.0),
            "vd_std": ("vd_std_m_s", 1.0),
            "fix": ("fix_type", 1.0),
            "hdop": ("hdop", 1.0),
        },
    ),
    "mag": (
        "sensors_mag",
        {"mx": ("mx_gauss", 1.0), "my": ("my_gauss", 1.0), "mz": ("mz_gauss", 1.0)},
    ),
    "baro": ("sensors_baro", {"baro_alt_m": ("alt_rel_m", 1.0)}),
    "compass": (
        "sensors_compass",
        {
            "heading_deg": ("heading_rad", 180.0 / math.pi),
            "pitch_deg": ("pitch_rad", 180.0 / math.pi),
            "roll_deg": ("roll_rad", 180.0 / math.pi),
        },
    ),
}


def _text(value: float) -> str:
    return "" if math.isnan(value) else repr(value)


def _rows(ulog: ULog, kind: str, offsets: dict[str, float]) -> Iterator[tuple[int, list[str]]]:
    topic, columns = COLUMNS[kind]
    try:
        data = ulog.get_dataset(topic).data
    except (KeyError, IndexError, ValueError):
        return
    for i, t_us in enumerate(data["timestamp"]):
        row = dict.fromkeys(HEADER, "")
        row["t"], row["kind"] = repr(int(t_us) / 1e6), kind
        for column, (field, scale) in columns.items():
            value = float(data[field][i])
            if column == "fix":
                row[column] = str(int(value))
            else:
                row[column] = _text(value * scale - offsets.get(column, 0.0))
        yield int(t_us), [row[c] for c in HEADER]


def logged_settings(ulog: ULog) -> dict[str, str]:
    """The navigator's settings a replay takes from the log's INFO, as logged (exact
    decimal text): ``declination_deg`` and ``gps_delay_s`` when set (not NaN)."""
    found = {}
    for name in ("declination_deg", "gps_delay_s"):
        text = str(ulog.msg_info_dict.get(f"nav.{name}", "nan"))
        try:
            number = float(text)
        except ValueError:
            continue
        if math.isfinite(number):
            found[name] = text
    return found


def replay_options(path: str | Path) -> list[str]:
    """The options that make ``companion replay`` of the CSV run the navigator with the
    settings the ULog's replay takes from its INFO."""
    settings = logged_settings(ULog(str(path), []))
    flags = {"declination_deg": "--declination", "gps_delay_s": "--gps-delay"}
    return [item for name, text in settings.items() for item in (flags[name], text)]


def sensor_log_rows(path: str | Path) -> Iterator[list[str]]:
    """The sensor rows of a ULog file, oldest first; at equal times in the order the
    navigator reads its inputs in, as a replay of the ULog itself feeds them (a kind's own
    order kept). Compass headings are written magnetic: a vehicle with a declination set
    (INFO ``nav.declination_deg``) made them true, so that declination is taken off again."""
    ulog = ULog(str(path), [topic for topic, _ in COLUMNS.values()])
    declination = float(logged_settings(ulog).get("declination_deg", 0.0))
    offsets = {"heading_deg": declination} if declination else {}
    kinds = sorted(COLUMNS, key=lambda kind: FEED_ORDER.index(f"sensors/{kind}"))
    streams: list[Any] = [_rows(ulog, kind, offsets) for kind in kinds]
    for _t, row in heapq.merge(*streams, key=lambda item: item[0]):
        yield row


def write_sensor_log(path: str | Path, out: TextIO) -> int:
    """Write the CSV sensor log of a ULog file; the number of rows."""
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(HEADER)
    count = 0
    for row in sensor_log_rows(path):
        writer.writerow(row)
        count += 1
    return count
