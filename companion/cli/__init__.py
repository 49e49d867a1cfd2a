"""The ``companion`` command: run a vehicle, fly it in simulation, look at it, check it.

Each command lives in its own module; importing them here, in the order ``--help`` lists
them, registers them on ``app``.
"""

from __future__ import annotations

import importlib

from companion.cli.app import app

__all__ = ["app", "main"]

for _module in (
    "companion.cli.vehicle",
    "ground.cli.sim",
    "ground.cli.replay",
    "ground.cli.campaign",
    "companion.cli.bridge",
):
    importlib.import_module(_module)


def main() -> None:
    """Console-script entry point."""
    app()
