"""``companion params``: the stopped vehicle's parameters, where each value comes from.

The values are the link's: the config's declarations (with the airframe file's defaults
and the facts the link fixes) and the stored set, ``params.json`` in the state directory,
which holds only what the user set. Run these with the vehicle stopped: a running link
keeps its own copy and writes it back on the next change from a ground station.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from companion.cli.app import CONFIG_OPT, EXIT_CONFIG, app, err, load_checked, out

params_app = typer.Typer(help="Parameters: list, diff, set, reset, .params files (stopped).")
app.add_typer(params_app, name="params")


def _param_store(config: Path):
    from companion.link.px4_compat import vehicle_facts
    from companion.params import ParamStore

    cfg = load_checked(config, None)
    decls = [d for spec in cfg.plugins for d in spec.params]
    facts = vehicle_facts(decls, cfg.sysid, {spec.kind: spec.settings for spec in cfg.plugins})
    return cfg, ParamStore(facts, Path(cfg.vehicle["state_dir"]) / "params.json")


def _refused(exc: Exception) -> typer.Exit:
    err.print(f"[red]params error:[/red] {exc}", highlight=False, soft_wrap=True)
    return typer.Exit(EXIT_CONFIG)


def _number(value: float) -> str:
    return f"{value:g}" if math.isfinite(value) else str(value)


@params_app.command("list")
def params_list(config: Annotated[Path, CONFIG_OPT]) -> None:
    """Every parameter, its value and where the value comes from: the declared default, the
    airframe file, or stored (set by the user; its default shown beside it)."""
    _, store = _param_store(config)
    for name in store.names:
        source = store.source(name)
        if source == "stored":
            decl = store.decls[name]
            source = f"stored (default {_number(decl.default)}, {decl.origin})"
        out.print(f"{name:16} {_number(store.get(name)):>12}  {source}", highlight=False)


@params_app.command("diff")
def params_diff(config: Annotated[Path, CONFIG_OPT]) -> None:
    """What the user set that differs from the defaults (declared or airframe)."""
    _, store = _param_store(config)
    shown = 0
    for name in sorted(store.stored):
        decl = store.decls[name]
        if store.values[name] != decl.default:
            value, default = _number(store.values[name]), _number(decl.default)
            out.print(f"{name:16} {value:>12}  default {default} ({decl.origin})", highlight=False)
            shown += 1
    for name, value in sorted(store.foreign.items()):
        out.print(f"{name:16} {value!s:>12}  stored, not declared by this config", highlight=False)
        shown += 1
    if not shown:
        out.print("every parameter at its default", highlight=False)


@params_app.command("set")
def params_set(
    name: Annotated[str, typer.Argument(help="parameter name")],
    value: Annotated[float, typer.Argument(help="new value (its default: follow it again)")],
    config: Annotated[Path, CONFIG_OPT],
) -> None:
    """Set and store one parameter, checked against its declaration."""
    from companion.params import ParamError

    _, store = _param_store(config)
    try:
        store.write(name, value)
    except ParamError as exc:
        raise _refused(exc) from None
    out.print(f"{name} = {_number(store.get(name))} ({store.source(name)})", highlight=False)


@params_app.command("reset")
def params_reset(config: Annotated[Path, CONFIG_OPT]) -> None:
    """Every parameter back to its default: the stored set emptied."""
    _, store = _param_store(config)
    changed = store.reset()
    out.print(f"stored set emptied, {len(changed)} values changed", highlight=False)


@params_app.command("save")
def params_save(
    file: Annotated[Path, typer.Argument(help=".params file to write")],
    config: Annotated[Path, CONFIG_OPT],
) -> None:
    """Write every parameter's value to a QGroundControl .params file."""
    from companion.params.qgc_file import save_params

    cfg, store = _param_store(config)
    save_params(store, file, sysid=cfg.sysid)
    out.print(f"{len(store)} parameters written to {file}")


@params_app.command("load")
def params_load(
    file: Annotated[
        Path,
        typer.Argument(
            help="QGroundControl .params, MAVProxy param save or Mission Planner .param"
        ),
    ],
    config: Annotated[Path, CONFIG_OPT],
) -> None:
    """Check a parameter file (QGroundControl's, MAVProxy's or Mission Planner's) against
    the config's declarations and store it (all or nothing); a line at its parameter's
    default stores nothing."""
    from companion.params import ParamError
    from companion.params.qgc_file import load_params

    _, store = _param_store(config)
    try:
        count = load_params(store, file)
    except (ParamError, OSError) as exc:
        raise _refused(exc) from None
    out.print(f"{count} parameters loaded from {file} into {store.path}")
