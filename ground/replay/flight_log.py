"""An on-board flight log (ULog) as replay input: its sensor samples and the estimate the
vehicle made in flight, read with pyulog.

The samples come back as the very bus messages the drivers published (every field, at
the precision it was logged), merged in time order; ``nav/state`` is what the vehicle's
navigator said, for comparing a replay with the flight.

pyulog (the ``ground`` extra) is imported only when a ULog is read: ``companion replay`` of
a CSV sensor log imports this module too, and works on an on-board install without it.
"""

from __future__ import annotations

import ctypes
import heapq
import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from companion.flight_log import topic_name
from companion.messages import Message, NavFlags, NavState
from companion.messages.channels import CHANNELS
from companion.navigation.estimate_csv import EstimateWriter
from companion.navigation.sample_order import FEED_ORDER
from companion.sensors.sensorlog import LogStats

SENSOR_CHANNELS = ("sensors/imu", "sensors/gps", "sensors/mag", "sensors/baro", "sensors/compass")
NAV_CHANNEL = "nav/state"
EARTH_RADIUS_M = 6_371_000.0

if TYPE_CHECKING:
    from pyulog import ULog


def is_flight_log(path: Path) -> bool:
    """Whether replay should read the file as an on-board ULog (by its name)."""
    return path.suffix.lower() == ".ulg"


def load(path: Path) -> ULog:
    """The log with only what replay uses parsed."""
    from pyulog import ULog
    from pyulog.exceptions import ULogException

    try:
        return ULog(str(path), [topic_name(c) for c in (*SENSOR_CHANNELS, NAV_CHANNEL)])
    except (OSError, ValueError, IndexError, KeyError, ULogException) as exc:
        raise ValueError(f"{path}: not a readable ULog file ({exc})") from None


def _columns(msg_type: type[Message], data: dict[str, np.ndarray]) -> list[tuple[str, Any]]:
    """(field, values) for every field; an array field's values are one column per element."""
    columns: list[tuple[str, Any]] = []
    for name, ctype, *_ in msg_type._fields_:
        if name == "t_us":
            columns.append((name, data["timestamp"]))
        elif issubclass(ctype, ctypes.Array):
            length = int(getattr(ctype, "_length_"))  # noqa: B009 - ctypes' own attribute
            columns.append((name, [data[f"{name}[{i}]"] for i in range(length)]))
        else:
            columns.append((name, data[name]))
    return columns


def messages(ulog: ULog, channel: str) -> Iterator[Message]:
    """One channel's logged samples as its registry messages (none if it was not logged)."""
    msg_type = CHANNELS[channel].type
    try:
        data = ulog.get_dataset(topic_name(channel)).data
        columns = _columns(msg_type, data)
    except (KeyError, IndexError, ValueError):
        return
    for i in range(len(data["timestamp"])):
        msg = msg_type()
        for name, values in columns:
            if isinstance(values, list):
                getattr(msg, name)[:] = [v[i].item() for v in values]
            else:
                setattr(msg, name, values[i].item())
        yield msg


def sensor_samples(ulog: ULog, stats: LogStats | None = None) -> Iterator[Message]:
    """Every sensor sample of the log, oldest first; at equal times in the order the
    navigator reads its inputs in (a channel's own order kept)."""
    stats = stats if stats is not None else LogStats()
    kinds = {c: c.split("/", 1)[1] for c in SENSOR_CHANNELS}
    channels = sorted(SENSOR_CHANNELS, key=lambda c: FEED_ORDER.index(c))
    streams = [((m, kinds[c]) for m in messages(ulog, c)) for c in channels]
    for msg, kind in heapq.merge(*streams, key=lambda item: item[0].t_us):
        stats.rows += 1
        stats.by_kind[kind] = stats.by_kind.get(kind, 0) + 1
        yield msg


def navigator_settings(ulog: ULog) -> dict[str, float | None]:
    """The settings the vehicle's navigator flew with (INFO ``nav.*``, as the logger
    records them; NaN, "not set", as None); empty for a log without them."""
    settings: dict[str, float | None] = {}
    for key, value in ulog.msg_info_dict.items():
        if not key.startswith("nav.") or key == "nav.plugin":
            continue
        try:
            number = float(value)
        except (TypeError, ValueError):
            continue  # a hostile or foreign log: the setting is left at its default
        settings[key[4:]] = None if math.isnan(number) else number
    return settings


def sample_count(ulog: ULog) -> int:
    """How many sensor samples the log holds (for a progress bar)."""
    total = 0
    for channel in SENSOR_CHANNELS:
        try:
            total += len(ulog.get_dataset(topic_name(channel)).data["timestamp"])
        except (KeyError, IndexError, ValueError):
            continue
    return total


@dataclass
class FlightComparison:
    """How far a replay's estimate is from the one the vehicle made in flight, at the
    flight's logged solution times (the replay's newest solution at or before each: the
    very same instant when the replay runs on the navigator's grid)."""

    compared: int = 0  # solutions with a valid position in both
    horizontal_rms_m: float = math.nan
    horizontal_max_m: float = math.nan
    altitude_rms_m: float = math.nan
    yaw_rms_deg: float = math.nan
    tilt_rms_deg: float = math.nan  # roll and pitch together


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2 * np.pi) - np.pi


def _table(states: list[NavState]) -> dict[str, np.ndarray]:
    names = ("t_us", "lat_deg", "lon_deg", "alt_msl_m", "roll_rad", "pitch_rad", "yaw_rad")
    table = {n: np.array([getattr(s, n) for s in states], dtype=float) for n in names}
    table["valid"] = np.array([bool(s.flags & NavFlags.POSITION_VALID) for s in states])
    return table


def compare(replayed: list[NavState], flown: list[NavState]) -> FlightComparison:
    """The replay against the flight's own estimate."""
    result = FlightComparison()
    if not replayed or not flown:
        return result
    # The flight's log may miss some of its solutions (``nav/state`` keeps only the newest):
    # each logged one is compared, none is stood in for by an older one.
    a, b = _table(flown), _table(replayed)
    index = np.searchsorted(b["t_us"], a["t_us"], side="right") - 1
    use = (index >= 0) & a["valid"]
    index = np.clip(index, 0, None)
    use &= b["valid"][index]
    if not use.any():
        return result
    at = {k: v[use] for k, v in a.items()}
    bt = {k: v[index[use]] for k, v in b.items()}
    north = np.radians(at["lat_deg"] - bt["lat_deg"]) * EARTH_RADIUS_M
    east = (
        np.radians(at["lon_deg"] - bt["lon_deg"])
        * EARTH_RADIUS_M
        * np.cos(np.radians(bt["lat_deg"]))
    )
    horizontal = np.hypot(north, east)
    tilt = np.concatenate([_wrap(at["roll_rad"] - bt["roll_rad"]),
                           _wrap(at["pitch_rad"] - bt["pitch_rad"])])  # fmt: skip
    result.compared = int(use.sum())
    result.horizontal_rms_m = float(np.sqrt(np.mean(horizontal**2)))
    result.horizontal_max_m = float(horizontal.max())
    result.altitude_rms_m = float(np.sqrt(np.mean((at["alt_msl_m"] - bt["alt_msl_m"]) ** 2)))
    yaw = _wrap(at["yaw_rad"] - bt["yaw_rad"])
    result.yaw_rms_deg = math.degrees(float(np.sqrt(np.mean(yaw**2))))
    result.tilt_rms_deg = math.degrees(float(np.sqrt(np.mean(tilt**2))))
    return result


def flight_estimate(ulog: ULog) -> list[NavState]:
    """What the vehicle's navigator published in flight."""
    return list(messages(ulog, NAV_CHANNEL))  # type: ignore[arg-type]


def as_track(states: list[NavState]) -> dict[str, np.ndarray]:
    """The flight's estimate in the columns of an estimate CSV (for the plot)."""
    valid = [s for s in states if s.flags & NavFlags.POSITION_VALID]
    names = {"t": "t_us", "lat": "lat_deg", "lon": "lon_deg", "alt": "alt_msl_m",
             "roll": "roll_rad", "pitch": "pitch_rad", "yaw": "yaw_rad"}  # fmt: skip
    track = {k: np.array([getattr(s, n) for s in valid], dtype=float) for k, n in names.items()}
    track["t"] = track["t"] / 1e6
    return track


def write_flight_estimate(path: Path, out: Path) -> int:
    """The estimate the vehicle made in flight, as an estimate CSV; the rows written."""
    writer = EstimateWriter(out)
    try:
        for s in flight_estimate(load(path)):
            if s.flags & NavFlags.POSITION_VALID:
                writer.add(s.t_us / 1e6, s.roll_rad, s.pitch_rad, s.yaw_rad, s.lat_deg,
                           s.lon_deg, s.alt_msl_m, s.vn_m_s, s.ve_m_s, s.vd_m_s)  # fmt: skip
    finally:
        writer.close()
    return writer.rows
