"""The ``companion`` command's first step: a plain ``companion run`` goes to the vehicle at once.

The command line (``companion.cli``: typer, rich, pydantic and every command's module, the
ground commands found through entry points) costs a third of a second of CPU to import,
several seconds of wall time on a loaded two-core board, and ``companion run`` hands its
process over to the vehicle right after parsing its three options anyway (``handover``).
A vehicle restarted in the air (its service, after the supervisor died) waited for all
of it before the first plug-in started. So ``companion run --config FILE [--namespace NS]
[--log-level LEVEL]`` runs the vehicle in this process without loading the command line;
anything else (help, another command, an option it does not know, a config that is not a
file) goes through the command line, which says what is wrong.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

_OPTIONS = {
    "--config": "config",
    "-c": "config",
    "--namespace": "namespace",
    "-n": "namespace",
    "--log-level": "log_level",
}


def run_options(argv: list[str]) -> tuple[str, str | None, str] | None:
    """(config, namespace, log level) of a plain ``run`` command line; None otherwise."""
    if not argv or argv[0] != "run":
        return None
    found: dict[str, str] = {}
    rest = argv[1:]
    while rest:
        name, *value = rest[0].split("=", 1) if rest[0].startswith("--") else [rest[0]]
        if not value:
            value, rest = rest[1:2], rest[1:]
        rest = rest[1:]
        key = _OPTIONS.get(name)
        if key is None or key in found or not value:
            return None
        found[key] = value[0]
    if not Path(found.get("config", "")).is_file():
        return None
    return found["config"], found.get("namespace"), found.get("log_level", "INFO")


def main() -> None:
    """Console-script entry point (and ``python -m companion``)."""
    options = run_options(sys.argv[1:])
    if options is None:
        from companion.cli import main as cli_main

        cli_main()
        return
    # As the command line does: one BLAS thread, set before numpy loads (no thread in the
    # supervisor when it forks its fork server).
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    from companion.exec_control.vehicle_process import run_vehicle

    sys.exit(run_vehicle(*options))
