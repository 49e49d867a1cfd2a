"""``companion run``, ``status``, ``graph``, and the stopped vehicle's missions."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated

import typer

from companion.cli.app import (
    CONFIG_OPT,
    NS_OPT,
    app,
    err,
    load_checked,
    out,
    plan_or_exit,
)


@app.command()
def run(
    config: Annotated[Path, CONFIG_OPT],
    namespace: Annotated[str | None, NS_OPT] = None,
    log_level: Annotated[str, typer.Option(help="DEBUG, INFO, WARNING")] = "INFO",
) -> None:
    """Run the vehicle: every plug-in of the config in its own process, supervised."""
    from companion.exec_control.handover import exec_module

    # The vehicle runs on in this process without the command line's libraries; it loads
    # and checks the config itself (a refused one: exit status 2, as every command).
    exec_module("companion.exec_control.vehicle_process", (str(config), namespace, log_level))


@app.command()
def graph(
    config: Annotated[Path, CONFIG_OPT],
    namespace: Annotated[str | None, NS_OPT] = None,
) -> None:
    """Check a config and print its channel graph (who writes and reads each channel)."""
    from companion.exec_control.topology import graph_lines

    cfg = load_checked(config, namespace)
    out.print(f"{cfg.path}: vehicle {cfg.name!r}, sysid {cfg.sysid}, bus {cfg.namespace!r}")
    for spec in cfg.plugins:
        out.print(f"  {spec.name:16} {spec.kind:28} {spec.group}")
    for line in graph_lines(cfg):
        out.print(line, highlight=False)


@app.command()
def status(
    namespace: Annotated[str | None, NS_OPT] = None,
    as_json: Annotated[bool, typer.Option("--json", help="machine-readable output")] = False,
    timeout: Annotated[float, typer.Option(help="seconds to wait for the table")] = 3.0,
) -> None:
    """Print the health table of a running vehicle (read from its bus)."""
    from companion.bus.namespace import default_namespace
    from companion.cli.status_view import health_dict, health_table, read_health

    ns = namespace or default_namespace()
    msg = read_health(ns, timeout)
    if msg is None:
        err.print(f"no vehicle is publishing system/health on bus {ns!r}")
        raise typer.Exit(1)
    if as_json:
        sys.stdout.write(json.dumps(health_dict(msg), indent=2) + "\n")
    else:
        out.print(health_table(msg))


mission_app = typer.Typer(help="Missions in QGroundControl .plan files (vehicle stopped).")
app.add_typer(mission_app, name="mission")


def _mission_store(config: Path):
    from companion.control.mission.mission_files import MissionStore

    cfg = load_checked(config, None)
    return MissionStore(Path(cfg.vehicle["state_dir"]) / "missions")


@mission_app.command("load")
def mission_load(
    plan: Annotated[Path, typer.Argument(help=".plan file to store as the vehicle's mission")],
    config: Annotated[Path, CONFIG_OPT],
) -> None:
    """Check a .plan (mission, fence, rally) and store it; all or nothing."""
    store = _mission_store(config)
    lists = plan_or_exit(plan)
    for mission_type, items in lists.items():
        store.replace(mission_type, items)
    out.print(f"stored {_counts({t: len(items) for t, items in lists.items()})} items from {plan}")
    from companion.control.mission.items import not_carried_note

    if (note := not_carried_note([it for items in lists.values() for it in items])) is not None:
        out.print(note)


@mission_app.command("save")
def mission_save(
    plan: Annotated[Path, typer.Argument(help=".plan file to write")],
    config: Annotated[Path, CONFIG_OPT],
) -> None:
    """Write the vehicle's stored mission, fence and rally points as a .plan file."""
    from companion.control.mission.plan import save_plan

    store = _mission_store(config)
    written = save_plan(plan, store.items)
    out.print(f"wrote {_counts(written)} items to {plan}")


def _counts(by_type: dict[int, int]) -> str:
    """``6 mission, 4 fence, 1 rally`` (by mission type 0, 1, 2)."""
    names = {0: "mission", 1: "fence", 2: "rally"}
    return ", ".join(f"{by_type.get(t, 0)} {name}" for t, name in names.items())
