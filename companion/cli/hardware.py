"""``companion check``: the config's devices on the bench, one line each and what to do."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from companion.cli.app import CONFIG_OPT, app, load_checked, out


def _rate(report) -> str:
    expected = report.probe.rate_hz
    if report.probe.stream is None or report.error:
        return "-"
    measured = f"{report.rate_hz:.1f}/s"
    return f"{measured} of {expected:g}/s" if expected > 0 else measured


def _table(result) -> Table:
    table = Table(title="Devices", title_justify="left")
    for column in ("plug-in", "device", "baud", "bytes", "frames", "bad", "rate", "verdict"):
        table.add_column(
            column, justify="right" if column in ("bytes", "frames", "bad") else "left"
        )
    for r in result.devices:
        name = f"{r.plugin} ({r.probe.what})" if r.probe.what else r.plugin
        counts = (str(r.bytes_in), str(r.frames_ok), str(r.frames_bad))
        if r.probe.stream is None:
            counts = (f"{r.written} out", "-", "-")
        verdict = "[green]ok[/green]" if r.ok else "[red]FAIL[/red]"
        table.add_row(name, r.probe.device, str(r.probe.baud), *counts, _rate(r), verdict)
    return table


@app.command()
def check(
    config: Annotated[Path, CONFIG_OPT],
    seconds: Annotated[
        float, typer.Option(help="how long each device is heard", min=0.5, max=600)
    ] = 4.0,
) -> None:
    """Open every device of the config for a few seconds: bytes, frames, bad frames, rate.

    Exit status 0 only when every device answers (the vehicle must not be running: it
    holds the same devices).
    """
    from companion.exec_control.bench_check import check_config

    cfg = load_checked(config, None)
    result = check_config(cfg, seconds)
    if not result.devices:
        out.print(f"{cfg.path}: no plug-in of this config has a device")
    else:
        out.print(_table(result))
    for r in result.devices:
        name = f"{r.plugin} ({r.probe.what})" if r.probe.what else r.plugin
        mark = "ok  " if r.ok else "FAIL"
        out.print(f"{mark} {name}: {r.advice}", highlight=False, soft_wrap=True)
    for problem in result.problems:
        out.print(f"FAIL {problem}", highlight=False, soft_wrap=True)
    raise typer.Exit(0 if result.ok else 1)
