"""``companion replay``: navigators over recorded sensor logs, one or many."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from companion.cli.app import (
    EXIT_CONFIG,
    app,
    err,
    out,
)
from companion.exec_control.vehicle_process import setup_logging
from ground.cli.extras import require_ground_extra


@app.command()
def replay(
    logs: Annotated[
        list[str],
        typer.Argument(
            metavar="LOG",
            help="sensor log CSVs (the design's format) or on-board flight logs (.ulg), "
            "folders of them or quoted patterns",
        ),
    ],
    out_path: Annotated[
        Path, typer.Option("--out", "-o", help="estimate CSV to write (a directory for many logs)")
    ],
    navigator: Annotated[str, typer.Option(help="ins_ekf or gps_compass")] = "ins_ekf",
    plot: Annotated[
        Path | None, typer.Option(help="also draw the flight into this PNG (many: a directory)")
    ] = None,
    truth: Annotated[Path | None, typer.Option(help="truth CSV to draw beside it")] = None,
    rate: Annotated[
        float | None,
        typer.Option(
            help="estimate rows per second of log time (default 50; an on-board log: the "
            "rate its navigator published at)"
        ),
    ] = None,
    declination: Annotated[
        float | None,
        typer.Option(
            help="magnetic declination, degrees east (compass, magnetometer); "
            "default: an on-board log's own setting, else the World Magnetic Model's"
        ),
    ] = None,
    gps_delay: Annotated[
        float | None,
        typer.Option(
            help="ins_ekf: seconds a fix reaches the navigator after it was measured (the nav "
            "plug-in's gps_delay_s); default: an on-board log's own setting, else measured"
        ),
    ] = None,
    address: Annotated[
        str | None, typer.Option(help="many logs: Ray cluster address (default: local)")
    ] = None,
    cpus: Annotated[int | None, typer.Option(help="many logs: CPUs of the local Ray")] = None,
) -> None:
    """Run a navigator over recorded sensor logs, offline, as fast as it goes.

    Several logs, a folder or a pattern run on Ray; --out is then a directory.
    """
    from companion.navigation.offline import NAVIGATORS
    from ground.replay.batch import is_batch

    if navigator not in NAVIGATORS:
        raise typer.BadParameter(f"navigator must be one of {', '.join(NAVIGATORS)}")
    setup_logging("WARNING")
    if plot is not None:
        require_ground_extra("replay --plot", "matplotlib")
    if is_batch(logs):
        require_ground_extra("replay (many logs)", "ray")
        if truth is not None:
            raise typer.BadParameter("--truth goes with a single log")
        _replay_batch(logs, out_path, navigator, plot, rate, declination, address, cpus)
    else:
        _replay_one(Path(logs[0]), out_path, navigator, plot, truth, rate, declination, gps_delay)


def _replay_one(
    log: Path, out_path: Path, navigator: str, plot: Path | None, truth: Path | None,
    rate: float | None, declination: float | None, gps_delay: float | None = None,
) -> None:  # fmt: skip
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from ground.replay.flight_log import is_flight_log
    from ground.replay.single import count_rows, replay_log

    if not log.is_file():
        err.print(f"[red]{log}: no such file[/red]", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG)
    if is_flight_log(log):  # a CSV sensor log replays on an on-board install; a ULog not
        require_ground_extra("replay FLIGHT.ulg", "pyulog")
    fixes: list = []
    percent = TextColumn("{task.percentage:>3.0f}%")
    columns = (TextColumn("{task.description}"), BarColumn(), percent, TimeRemainingColumn())
    with Progress(*columns, console=err, transient=True) as bar:
        task = bar.add_task(f"{navigator} over {log.name}", total=count_rows(log))
        try:
            summary, states = replay_log(
                log, navigator, out_path, rate, declination,
                lambda n: bar.advance(task, n), fixes if plot else None, gps_delay,
            )  # fmt: skip
        except ValueError as exc:
            err.print(f"[red]{exc}[/red]", highlight=False, soft_wrap=True)
            raise typer.Exit(EXIT_CONFIG) from None
    _print_replay_summary(summary)
    if plot is not None:
        from companion.navigation.estimate_csv import read_estimate
        from ground.replay.flight_log import as_track
        from ground.replay.plot import plot_replay

        reference, label = (read_estimate(truth), "truth") if truth else (None, "")
        if reference is None and summary.flown:
            reference, label = as_track(summary.flown), "in flight"
        plot_replay(states, plot, f"{log.name}: {navigator}", fixes, reference, label)
        err.print(f"plot written to {plot}")


def _replay_batch(
    args: list[str], out_dir: Path, navigator: str, plot: Path | None, rate: float | None,
    declination: float | None, address: str | None, cpus: int | None,
) -> None:  # fmt: skip
    from ground.replay.batch import (
        SUMMARY_NAME,
        LogsError,
        find_logs,
        replay_logs,
        summary_table,
    )  # fmt: skip

    try:
        logs = find_logs(args, out_dir)
    except LogsError as exc:
        err.print(f"[red]{exc}[/red]", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None
    rate = rate or 50.0
    rows = replay_logs(logs, out_dir, navigator, rate, declination, plot, address, cpus, err)
    out.print(summary_table(rows, f"{navigator} over {len(rows)} logs"))
    failed = sum(1 for r in rows if r.error)
    out.print(f"{len(rows) - failed} ok, {failed} failed; summary {out_dir / SUMMARY_NAME}")
    raise typer.Exit(1 if failed else 0)


def _print_replay_summary(s) -> None:
    out.print(
        f"{s.log}: {s.rows} rows ({s.bad_rows} bad), {s.log_seconds:.1f} s of log in "
        f"{s.wall_seconds:.1f} s ({s.speed:.0f}x) -> {s.estimates} estimates"
    )
    out.print(
        f"innovation rejections: GPS {s.gps_rejected}, heading {s.heading_rejected}; "
        f"longest GPS gap {s.longest_outage_s:.1f} s; final horizontal 1-sigma "
        f"{s.final_pos_std_m:.1f} m; samples flagged {s.flagged}"
    )
    f = s.flight
    if f is not None:
        out.print(
            f"against the estimate made in flight ({f.compared} solutions): horizontal "
            f"RMS {f.horizontal_rms_m:.2f} m (max {f.horizontal_max_m:.2f} m), altitude RMS "
            f"{f.altitude_rms_m:.2f} m, tilt RMS {f.tilt_rms_deg:.2f}°, yaw RMS "
            f"{f.yaw_rms_deg:.2f}°"
        )
