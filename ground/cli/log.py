"""``companion log``: an on-board flight log (ULog) as the sensor log CSV replay reads."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from companion.cli.app import EXIT_CONFIG, app, err, out
from ground.cli.extras import require_ground_extra


@app.command()
def log(
    ulog: Annotated[Path, typer.Argument(metavar="FLIGHT.ulg", help="an on-board flight log")],
    out_path: Annotated[Path, typer.Option("--out", "-o", help="sensor log CSV to write")],
    estimate: Annotated[
        Path | None,
        typer.Option(help="also write the estimate the vehicle made in flight (estimate CSV)"),
    ] = None,
) -> None:
    """Convert an on-board ULog flight log to the sensor log CSV `companion replay` reads
    (and, with --estimate, the vehicle's own navigation estimate)."""
    require_ground_extra("log", "pyulog")
    from ground.flight_log_csv import replay_options, write_sensor_log

    if not ulog.is_file():
        err.print(f"[red]no such log: {ulog}[/red]")
        raise typer.Exit(EXIT_CONFIG)
    try:
        with out_path.open("w", newline="") as handle:
            rows = write_sensor_log(ulog, handle)
        options = replay_options(ulog)
        if estimate is not None:
            from ground.replay.flight_log import write_flight_estimate

            out.print(
                f"{write_flight_estimate(ulog, estimate)} estimate rows written to {estimate}"
            )
    except (OSError, ValueError, IndexError) as exc:
        err.print(f"[red]cannot convert {ulog}: {exc}[/red]")
        raise typer.Exit(EXIT_CONFIG) from None
    out.print(f"{rows} sensor rows written to {out_path}")
    if options:  # the navigator's settings were in the log's INFO, the CSV has no place
        out.print(
            f"replay it with the settings flown: companion replay {out_path} {' '.join(options)}",
            highlight=False,
            soft_wrap=True,
        )
