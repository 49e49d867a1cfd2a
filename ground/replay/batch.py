"""`companion replay` over many logs at once, on Ray, with a summary of navigator health.

Each log is one Ray task running ``replay_log`` (the single replay's own code) and
writing ``<out>/<stem>.estimate.csv``; the driver gathers the summaries as they finish,
draws the progress and writes ``<out>/summary.csv``. A log that cannot be replayed is a
failed row of the summary, never the end of the batch.
"""

from __future__ import annotations

import csv
import glob
import logging
import math
from dataclasses import dataclass
from pathlib import Path

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from ground.ray_session import as_completed, ray_session
from ground.replay.single import ReplaySummary, replay_log

log = logging.getLogger(__name__)
ESTIMATE_SUFFIX = ".estimate.csv"
SUMMARY_NAME = "summary.csv"
CPUS_PER_LOG = 1.0  # a replay is one Python thread
SUMMARY_COLUMNS = (
    "log", "status", "error", "rows", "bad_rows", "duration_s", "estimates", "wall_s",
    "gps_rejected", "heading_rejected", "gps_outages", "longest_gps_gap_s",
    "gps_outage_total_s", "final_pos_std_m", "final_alt_std_m", "final_vel_std_m_s",
    "final_tilt_std_deg", "final_yaw_std_deg",
)  # fmt: skip


class LogsError(ValueError):
    """The arguments name no log, or two logs would write the same estimate."""


def is_batch(args: list[str]) -> bool:
    """More than one path, a folder or a pattern: ``--out`` is then a directory."""
    if len(args) != 1:
        return True
    path = Path(args[0])
    return path.is_dir() or (glob.has_magic(args[0]) and not path.exists())


def find_logs(args: list[str], out_dir: Path) -> list[Path]:
    """The logs the arguments name, in their order, each once.

    A folder gives its ``*.csv`` files, a pattern its matches (expanded here, for when
    the shell did not). This command's own outputs are left out, so that a folder can
    hold its logs and their estimates.
    """
    own_summary = (out_dir / SUMMARY_NAME).resolve()
    found: dict[Path, Path] = {}
    for arg in args:
        path = Path(arg)
        if path.is_dir():
            matches = sorted(path.glob("*.csv"))
        elif glob.has_magic(arg) and not path.exists():
            matches = sorted(Path(m) for m in glob.glob(arg, recursive=True))
            if not matches:
                raise LogsError(f"{arg}: no file matches")
        else:
            matches = [path]  # a missing file fails as its own row
        for match in matches:
            if match.name.endswith(ESTIMATE_SUFFIX) or match.resolve() == own_summary:
                continue
            found.setdefault(match.resolve(), match)
    if not found:
        raise LogsError(f"no logs in {' '.join(args)}")
    _check_names(list(found.values()))
    return list(found.values())


def _check_names(logs: list[Path]) -> None:
    by_stem: dict[str, Path] = {}
    for path in logs:
        other = by_stem.setdefault(path.stem, path)
        if other is not path:
            raise LogsError(f"{other} and {path} would both write {path.stem}{ESTIMATE_SUFFIX}")


@dataclass(frozen=True)
class ReplayJob:
    """One log's replay, as a Ray task gets it (absolute paths: workers run elsewhere)."""

    log: Path
    out: Path
    navigator: str
    rate_hz: float = 50.0
    declination_deg: float | None = None
    plot: Path | None = None


def replay_job(job: ReplayJob) -> ReplaySummary:
    """The Ray task: replay one log, write its estimate (and plot); the summary back."""
    fixes: list | None = [] if job.plot is not None else None
    summary, states = replay_log(
        job.log, job.navigator, job.out, job.rate_hz, job.declination_deg, fixes=fixes
    )
    if job.plot is not None and states:
        from ground.replay.plot import plot_replay  # matplotlib only when drawing

        plot_replay(states, job.plot, f"{job.log.name}: {job.navigator}", fixes)
    return summary


@dataclass
class BatchRow:
    """One log's line of the summary."""

    log: Path
    error: str | None = None
    summary: ReplaySummary | None = None

    @property
    def status(self) -> str:
        """ok or failed."""
        return "failed" if self.error else "ok"


def replay_logs(
    logs: list[Path],
    out_dir: Path,
    navigator: str,
    rate_hz: float = 50.0,
    declination_deg: float | None = None,
    plot_dir: Path | None = None,
    address: str | None = None,
    cpus: int | None = None,
    console: Console | None = None,
) -> list[BatchRow]:
    """Replay every log on Ray into ``out_dir``, write ``summary.csv``; rows in log order."""
    out_dir = out_dir.resolve()  # Ray's workers run in other directories
    out_dir.mkdir(parents=True, exist_ok=True)
    if plot_dir is not None:
        plot_dir = plot_dir.resolve()
        plot_dir.mkdir(parents=True, exist_ok=True)
    jobs = [
        ReplayJob(log.resolve(), out_dir / f"{log.stem}{ESTIMATE_SUFFIX}", navigator, rate_hz,
                  declination_deg, plot_dir / f"{log.stem}.png" if plot_dir else None)
        for log in logs
    ]  # fmt: skip
    rows = run_batch(jobs, address, cpus, console)
    for row, path in zip(rows, logs, strict=True):
        row.log = path  # as the user named it, not as the workers were told
    write_summary(rows, out_dir / SUMMARY_NAME)
    return rows


def run_batch(
    jobs: list[ReplayJob],
    address: str | None = None,
    cpus: int | None = None,
    console: Console | None = None,
) -> list[BatchRow]:
    """Every job on Ray, one task per log; the rows in the jobs' order."""
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TextColumn("{task.fields[running]} running, {task.fields[failed]} failed"),
               TimeElapsedColumn())  # fmt: skip
    rows: dict[ReplayJob, BatchRow] = {}
    failed = 0
    with ray_session(address, cpus), Progress(*columns, console=console) as bar:
        task = bar.add_task("logs", total=len(jobs), running=0, failed=0)
        for done in as_completed(replay_job, jobs, CPUS_PER_LOG):
            row = rows[done.item] = _row(done.item, done.result, done.error)
            if row.error:
                failed += 1
                log.warning("%s: failed: %s", row.log, row.error)
                done.item.out.unlink(missing_ok=True)  # no partial estimate to mistake
            bar.update(task, advance=1, running=done.running, failed=failed)
    return [rows[job] for job in jobs]


def _row(job: ReplayJob, summary: ReplaySummary | None, error: str | None) -> BatchRow:
    if error is None and summary is not None and summary.estimates == 0:
        error = f"no estimate ({summary.rows} rows, {summary.bad_rows} bad)"
    return BatchRow(job.log, error, summary)


def _figures(row: BatchRow) -> dict[str, object]:
    s = row.summary
    figures: dict[str, object] = {"log": str(row.log), "status": row.status,
                                  "error": row.error or ""}  # fmt: skip
    if s is None:
        return figures
    figures.update(
        rows=s.rows, bad_rows=s.bad_rows, duration_s=round(s.log_seconds, 3),
        estimates=s.estimates, wall_s=round(s.wall_seconds, 3), gps_rejected=s.gps_rejected,
        heading_rejected=s.heading_rejected, gps_outages=s.outages,
        longest_gps_gap_s=round(s.longest_outage_s, 3),
        gps_outage_total_s=round(s.outage_total_s, 3),
        final_pos_std_m=_num(s.final_pos_std_m), final_alt_std_m=_num(s.final_alt_std_m),
        final_vel_std_m_s=_num(s.final_vel_std_m_s),
        final_tilt_std_deg=_num(s.final_tilt_std_deg),
        final_yaw_std_deg=_num(s.final_yaw_std_deg),
    )  # fmt: skip
    return figures


def _num(value: float) -> float | str:
    return round(value, 4) if math.isfinite(value) else ""


def write_summary(rows: list[BatchRow], path: Path) -> None:
    """``summary.csv``: one line per log, blank where a failed log has no figure."""
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, SUMMARY_COLUMNS, restval="")
        writer.writeheader()
        for row in rows:
            writer.writerow(_figures(row))


_TABLE = (  # (summary.csv column, heading)
    ("rows", "rows"), ("duration_s", "log s"), ("gps_rejected", "GPS rej"),
    ("heading_rejected", "hdg rej"), ("gps_outages", "outages"),
    ("longest_gps_gap_s", "longest gap s"), ("gps_outage_total_s", "outage s"),
    ("final_pos_std_m", "σ pos m"), ("final_alt_std_m", "σ alt m"),
    ("final_vel_std_m_s", "σ vel m/s"), ("final_tilt_std_deg", "σ tilt °"),
    ("final_yaw_std_deg", "σ yaw °"),
)  # fmt: skip


def summary_table(rows: list[BatchRow], title: str) -> Table:
    """The summary for the terminal: figures per log, failures in red with their error."""
    table = Table(title=title)
    table.add_column("log")
    table.add_column("status")
    for _, heading in _TABLE:
        table.add_column(heading, justify="right")
    table.add_column("error")
    for row in rows:
        figures = _figures(row)
        status = "[green]ok[/green]" if row.status == "ok" else "[red]failed[/red]"
        cells = [_cell(figures.get(key, "")) for key, _ in _TABLE]
        table.add_row(row.log.name, status, *cells, row.error or "")
    return table


def _cell(value: object) -> str:
    if isinstance(value, float):
        return f"{value:.2f}"
    return str(value)
