"""The ground commands need the ``ground`` extra; say so plainly when it is missing."""

from __future__ import annotations

import importlib.util

import typer
from rich.markup import escape

from companion.cli.app import EXIT_CONFIG, err

INSTALL_HINT = (
    "install the ground tools: pip install 'companion[ground]' "
    "(from a checkout: uv sync --extra ground)"
)


def require_ground_extra(command: str, *modules: str) -> None:
    """Exit with an install hint if any of ``modules`` is not installed.

    Looked up, not imported: ``companion sim`` runs the vehicle's supervisor in this
    process, whose first fork server is forked from it; JSBSim imported here (~0.3 s) was
    mapped in every plug-in process while only the simulator bridge flies it.
    """
    missing = [name for name in modules if importlib.util.find_spec(name) is None]
    if missing:
        err.print(
            f"[red]companion {command} needs {', '.join(missing)}[/red], which the on-board "
            f"install leaves out: {escape(INSTALL_HINT)}",
            highlight=False,
            soft_wrap=True,
        )
        raise typer.Exit(EXIT_CONFIG)
