"""``companion campaign``: many simulated flights on Ray, scored and reported."""

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
def campaign(
    spec_file: Annotated[Path, typer.Argument(metavar="SPEC.toml", help="the campaign spec")],
    results: Annotated[
        Path | None, typer.Option("--out", help="results dir (default SPEC_results/)")
    ] = None,
    address: Annotated[str | None, typer.Option(help="Ray cluster (default: a local one)")] = None,
    cpus: Annotated[int | None, typer.Option(help="CPUs of the local Ray instance")] = None,
    retry_failed: Annotated[bool, typer.Option(help="fly failed flights again")] = False,
    log_level: Annotated[str, typer.Option(help="DEBUG, INFO, WARNING")] = "WARNING",
) -> None:
    """Fly every flight of a campaign in lockstep simulation on Ray; score, tabulate, report."""
    require_ground_extra("campaign", "jsbsim", "ray")
    from companion.exec_control.config import ConfigError
    from ground.campaign.runner import run_campaign
    from ground.campaign.spec import load_spec

    setup_logging(log_level, "campaign")
    try:
        spec = load_spec(spec_file)
    except ConfigError as exc:
        err.print(f"[red]campaign spec error:[/red] {exc}", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None
    out_dir = results or Path(f"{spec_file.stem}_results")
    outcome = run_campaign(spec, out_dir, address, cpus, retry_failed, console=err)
    out.print(
        f"{outcome.flown} flown ({outcome.failed} failed), {outcome.skipped} already done; "
        f"results {outcome.results}" + (f", report {outcome.report}" if outcome.report else "")
    )
    raise typer.Exit(1 if outcome.failed else 0)
