"""The ``companion`` command's app, consoles and the helpers every command shares."""

from __future__ import annotations

import sys
from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape

from companion.exec_control.vehicle_process import EXIT_CONFIG

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="On-board software of a MAVLink-speaking fixed-wing UAV companion computer.",
)
err = Console(stderr=True)
# A pipe gets a wide console so the status table is not folded into unreadable columns.
out = Console() if sys.stdout.isatty() else Console(width=200)

CONFIG_OPT = typer.Option("--config", "-c", help="vehicle config (TOML)")
NS_OPT = typer.Option("--namespace", "-n", help="bus namespace (default: config or $COMPANION_BUS)")


def load_checked(config: Path, namespace: str | None):
    from companion.exec_control.config import ConfigError, load_config
    from companion.exec_control.topology import check_topology

    try:
        cfg = load_config(config, namespace)
        check_topology(cfg)
    except ConfigError as exc:
        # Escaped: a message may quote a table ("[vehicle]"), which is not markup.
        err.print(f"[red]config error:[/red] {escape(str(exc))}", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None
    return cfg


def plan_or_exit(plan: Path):
    from companion.control.mission.plan import PlanError, checked_plan

    try:
        return checked_plan(plan)
    except PlanError as exc:
        err.print(f"[red]plan error:[/red] {exc}", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_CONFIG) from None
