"""The ground commands need the ``ground`` extra; say so plainly when it is missing."""

from __future__ import annotations

import importlib

import typer
from rich.markup import escape

from companion.cli.app import EXIT_CONFIG, err

INSTALL_HINT = (
    "install the ground tools: pip install 'companion[ground]' "
    "(from a checkout: uv sync --extra ground)"
)


def require_ground_extra(command: str, *modules: str) -> None:
    """Exit with an install hint if any of ``modules`` cannot be imported."""
    missing = []
    for name in modules:
        try:
            importlib.import_module(name)
        except ImportError:
            missing.append(name)
    if missing:
        err.print(
            f"[red]companion {command} needs {', '.join(missing)}[/red], which the on-board "
            f"install leaves out: {escape(INSTALL_HINT)}",
            highlight=False,
            soft_wrap=True,
        )
        raise typer.Exit(EXIT_CONFIG)
