"""``companion campaign SPEC.toml``: every flight of the spec on Ray, as they finish.

Flights already in the results table are skipped (a rerun resumes); each finished flight
is written at once; a flight whose task dies or overruns is recorded as failed and the
campaign goes on. The report is drawn from the whole table at the end.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from ground.campaign.flight_run import FlightJob, failed_row, fly_flight
from ground.campaign.report import write_report
from ground.campaign.results import ResultsTable
from ground.campaign.spec import CampaignSpec
from ground.ray_session import as_completed, ray_session

log = logging.getLogger(__name__)
RAY_GRACE_S = 120.0  # beyond the flight's own limit, before Ray cancels its task


@dataclass
class CampaignOutcome:
    """What the run did (the table holds the rest)."""

    flown: int
    skipped: int
    failed: int
    results: Path
    report: Path | None


def run_campaign(
    spec: CampaignSpec,
    out_dir: Path,
    address: str | None = None,
    cpus: int | None = None,
    retry_failed: bool = False,
    console: Console | None = None,
) -> CampaignOutcome:
    """Fly what is not done yet, record every flight, draw the report."""
    out_dir = out_dir.resolve()  # Ray's workers and the simulators run elsewhere
    table = ResultsTable(out_dir / "results.csv")
    done = table.done_ids(retry_failed)
    todo = [f for f in spec.flights if f.flight_id not in done]
    folder = str(out_dir / "flights")
    jobs = [FlightJob(f, folder, spec.flight_timeout_s, spec.silent_s) for f in todo]
    skipped = len(spec.flights) - len(todo)
    if skipped:
        log.info("%d flights already done: skipped", skipped)
    failed = 0
    if jobs:
        failed = _fly_all(jobs, spec, table, address, cpus, console)
    ids = {f.flight_id for f in spec.flights}
    rows = [r for k, r in table.rows.items() if k in ids]
    report = write_report(rows, out_dir, spec.name) if rows else None
    return CampaignOutcome(len(jobs), skipped, failed, table.path, report)


def _fly_all(
    jobs: list[FlightJob],
    spec: CampaignSpec,
    table: ResultsTable,
    address: str | None,
    cpus: int | None,
    console: Console | None,
) -> int:
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TextColumn("{task.fields[state]}"), TimeElapsedColumn())  # fmt: skip
    failed = 0
    with ray_session(address, cpus), Progress(*columns, console=console) as bar:
        task = bar.add_task(spec.name, total=len(jobs), state="starting")
        stream = as_completed(fly_flight, jobs, spec.cpus_per_flight,
                              timeout_s=spec.flight_timeout_s + RAY_GRACE_S)  # fmt: skip
        for done in stream:
            row = done.result if done.error is None else failed_row(done.item, done.error)
            table.add(row)
            if row["status"] != "ok":
                failed += 1
                log.warning("%s failed: %s", row["flight_id"], row["error"])
            state = f"{done.running} running, {failed} failed"
            bar.update(task, advance=1, state=state)
    return failed
