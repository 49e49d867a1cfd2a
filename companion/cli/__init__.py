"""The ``companion`` command: run a vehicle, look at it, check it; and, with the ground
tools installed, fly it in simulation, replay logs and run campaigns.

Each command lives in its own module; importing them here, in the order ``--help`` lists
them, registers them on ``app``. The ground commands live in the ``ground`` package, which
nothing on board imports: they are found through the ``companion.commands`` entry points.
"""

from __future__ import annotations

import os

# The vehicle's matrices are tiny: one BLAS thread (set before numpy loads), and so no
# thread in the supervisor when it forks its fork server.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import importlib  # noqa: E402
from importlib.metadata import entry_points  # noqa: E402

from companion.cli.app import app  # noqa: E402

__all__ = ["app", "main"]

COMMANDS_GROUP = "companion.commands"
HELP_ORDER = ("sim", "replay", "campaign")


def _help_rank(name: str) -> int:
    return HELP_ORDER.index(name) if name in HELP_ORDER else len(HELP_ORDER)


importlib.import_module("companion.cli.vehicle")
importlib.import_module("companion.cli.params")
for _entry in sorted(entry_points(group=COMMANDS_GROUP), key=lambda e: _help_rank(e.name)):
    importlib.import_module(_entry.value)
importlib.import_module("companion.cli.hardware")
importlib.import_module("companion.cli.service")
importlib.import_module("companion.cli.bridge")


def main() -> None:
    """Console-script entry point."""
    app()
