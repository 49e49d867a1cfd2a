"""``companion replay``: a navigator over a recorded sensor log, offline, in one process.

The navigator is the plug-in's own (``companion.navigation.offline.NAVIGATORS``); this
reads the log, shows progress, writes the estimate CSV and, on request, a plot.
"""

from __future__ import annotations

import dataclasses
import gc
import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from companion.messages import GpsFix, Message, NavFlags, NavState
from companion.navigation.estimate_csv import EstimateWriter
from companion.navigation.ins_config import InsEkfConfig
from companion.navigation.offline import (
    NAVIGATORS,
    InsEkfRunner,
    Navigator,
    run_as_plugin,
    run_navigator,
    true_headings,
)
from companion.sensors.sensorlog import LogStats, read_sensor_log
from ground.replay.flight_log import (
    FlightComparison,
    compare,
    flight_estimate,
    is_flight_log,
    load,
    navigator_settings,
    sensor_samples,
)

PROGRESS_ROWS = 2000
# A gap between fixes counts as an outage beyond this: twice the period of the slowest
# GPS receivers logged (1 Hz), so ordinary jitter is never one.
OUTAGE_MIN_S = 2.0
_POSITION_VALID = int(NavFlags.POSITION_VALID)


@dataclass
class ReplaySummary:
    """What a replay did and found."""

    log: Path
    navigator: str
    rows: int = 0
    bad_rows: int = 0
    estimates: int = 0
    log_seconds: float = 0.0
    wall_seconds: float = 0.0
    gps_rejected: int = 0
    heading_rejected: int = 0
    longest_outage_s: float = 0.0  # longest gap between fixes, outage or not
    outages: int = 0  # gaps longer than OUTAGE_MIN_S
    outage_total_s: float = 0.0
    final_pos_std_m: float = math.nan  # horizontal 1-sigma
    final_alt_std_m: float = math.nan
    final_vel_std_m_s: float = math.nan
    final_tilt_std_deg: float = math.nan  # the larger of roll and pitch
    final_yaw_std_deg: float = math.nan
    flagged: dict[str, int] = field(default_factory=dict)
    # An on-board log: the replay against the estimate the vehicle made in flight.
    flight: FlightComparison | None = None
    flown: list[NavState] = field(default_factory=list, repr=False)

    @property
    def speed(self) -> float:
        """Log time per wall time."""
        return self.log_seconds / self.wall_seconds if self.wall_seconds else math.inf


def count_rows(path: Path) -> int | None:
    """Data rows in a CSV file (for the progress bar); None for an on-board log."""
    if is_flight_log(path):
        return None  # it would be read twice
    with path.open("rb") as handle:
        return max(
            0, sum(chunk.count(b"\n") for chunk in iter(lambda: handle.read(1 << 20), b"")) - 1
        )


def _watch_gps(
    samples: Iterator[Message], summary: ReplaySummary, fixes: list[GpsFix] | None
) -> Iterator[Message]:
    """Pass samples through, measuring the longest gap between GPS fixes (and keeping them)."""
    last: int | None = None
    for sample in samples:
        if isinstance(sample, GpsFix) and sample.fix_type >= 2:
            if fixes is not None:
                fixes.append(sample)
            if last is not None:
                gap = (sample.t_us - last) / 1e6
                summary.longest_outage_s = max(summary.longest_outage_s, gap)
                if gap > OUTAGE_MIN_S:
                    summary.outages += 1
                    summary.outage_total_s += gap
            last = sample.t_us
        yield sample


def replay_log(
    log: Path,
    navigator: str,
    out: Path,
    rate_hz: float | None = None,
    declination_deg: float | None = None,
    progress: Callable[[int], None] | None = None,
    fixes: list[GpsFix] | None = None,
    gps_delay_s: float | None = None,
) -> tuple[ReplaySummary, list[NavState]]:
    """Run the navigator over the log; write the estimate; return a summary and the states.

    ``gps_delay_s`` (ins_ekf): how late fixes arrive, as the nav plug-in's setting; None:
    measured from the log. An on-board log runs ins_ekf as the plug-in did in flight: with
    the settings it logged (the arguments given here override them), its sample order and
    its publication grid (``rate_hz`` None: its own rate; otherwise 50 Hz)."""
    summary = ReplaySummary(log, navigator)
    stats = LogStats()
    if is_flight_log(log):
        ulog = load(log)
        summary.flown = flight_estimate(ulog)
        logged = navigator_settings(ulog)
        solutions = _flight_solutions(
            navigator, sensor_samples(ulog, stats), logged, rate_hz,
            {"declination_deg": declination_deg, "gps_delay_s": gps_delay_s}, summary, fixes,
        )  # fmt: skip
    else:
        if navigator == "ins_ekf" and gps_delay_s is not None:
            config = InsEkfConfig(declination_deg=declination_deg, gps_delay_s=gps_delay_s)
            nav: Navigator = InsEkfRunner(config=config)
        else:
            nav = NAVIGATORS[navigator](declination_deg)
        samples = _watch_gps(true_headings(read_sensor_log(log, stats), declination_deg),
                             summary, fixes)  # fmt: skip
        solutions = run_navigator(nav, samples, rate_hz or 50.0)
    states = _run(solutions, out, summary, stats, progress)
    if is_flight_log(log):
        summary.flight = compare(states, summary.flown)
    return summary, states


def _flight_solutions(
    navigator: str,
    source: Iterator[Message],
    logged: dict[str, float | None],
    rate_hz: float | None,
    given: dict[str, float | None],
    summary: ReplaySummary,
    fixes: list[GpsFix] | None,
) -> Iterator[NavState]:
    """An on-board log's samples are the bus's, as the navigator took them (compass
    headings already true): no conversion, the flight's settings unless overridden."""
    settings = {**logged, **{k: v for k, v in given.items() if v is not None}}
    samples = _watch_gps(source, summary, fixes)
    if navigator != "ins_ekf":
        nav = NAVIGATORS[navigator](settings.get("declination_deg"))
        return run_navigator(nav, samples, rate_hz or 50.0)
    names = {f.name for f in dataclasses.fields(InsEkfConfig)}
    config = InsEkfConfig(**{k: v for k, v in settings.items() if k in names})  # type: ignore[arg-type]
    rate = rate_hz or settings.get("publish_hz") or 50.0
    return run_as_plugin(InsEkfRunner(config=config), samples, rate)


def _run(
    solutions: Iterator[NavState],
    out: Path,
    summary: ReplaySummary,
    stats: LogStats,
    progress: Callable[[int], None] | None,
) -> list[NavState]:
    writer = EstimateWriter(out)
    states: list[NavState] = []
    started = time.perf_counter()
    # The loop makes hundreds of thousands of short-lived objects and no cycles: the
    # cyclic collector would only rescan the growing list of states (a quarter of the time).
    gc_was_enabled = gc.isenabled()
    gc.disable()
    try:
        for state in solutions:
            states.append(state)
            if state.flags & _POSITION_VALID:
                writer.add(state.t_us / 1e6, state.roll_rad, state.pitch_rad, state.yaw_rad,
                           state.lat_deg, state.lon_deg, state.alt_msl_m,
                           state.vn_m_s, state.ve_m_s, state.vd_m_s)  # fmt: skip
            if progress is not None and stats.rows - summary.rows >= PROGRESS_ROWS:
                progress(stats.rows - summary.rows)
                summary.rows = stats.rows
    finally:
        if gc_was_enabled:
            gc.enable()
        writer.close()
    if progress is not None:
        progress(stats.rows - summary.rows)
    summary.wall_seconds = time.perf_counter() - started
    _summarise(summary, stats, writer.rows, states)
    return states


def _summarise(summary: ReplaySummary, stats: LogStats, rows: int, states: list[NavState]) -> None:
    summary.rows, summary.bad_rows, summary.estimates = stats.rows, stats.bad, rows
    if not states:
        return
    end = states[-1]
    summary.log_seconds = (end.t_us - states[0].t_us) / 1e6
    summary.gps_rejected, summary.heading_rejected = end.gps_rejected, end.heading_rejected
    summary.final_pos_std_m = math.hypot(end.pos_std_m[0], end.pos_std_m[1])
    summary.final_alt_std_m = end.pos_std_m[2]
    summary.final_vel_std_m_s = math.hypot(*end.vel_std_m_s)
    # A navigator that does not estimate its attitude's uncertainty leaves it at zero,
    # which no filter's sigma ever is: unknown, not perfect.
    if any(end.att_std_rad):
        summary.final_tilt_std_deg = math.degrees(max(end.att_std_rad[0], end.att_std_rad[1]))
        summary.final_yaw_std_deg = math.degrees(end.att_std_rad[2])
    for flag in (NavFlags.DEAD_RECKONING, NavFlags.GPS_REJECTED, NavFlags.ALIGNING):
        bit = int(flag)
        summary.flagged[str(flag.name)] = sum(1 for s in states if s.flags & bit)
