"""``companion bridge``: processes that connect the vehicle to something outside it."""

from __future__ import annotations

import logging
from typing import Annotated

import typer

from companion.cli.app import (
    app,
)

bridge_app = typer.Typer(help="Bridges between the vehicle and something outside it.")
app.add_typer(bridge_app, name="bridge")


@bridge_app.command("legacy-text")
def bridge_legacy_text(
    serial: Annotated[str, typer.Option(help="the 25-byte text link: path, pyserial URL")],
    mavlink: Annotated[str, typer.Option(help="the vehicle: udpin://, udpout://, tcp://...")],
    baud: Annotated[int, typer.Option(help="the text link's baud rate")] = 9600,
    att_rate: Annotated[float, typer.Option(help="ATT frames a second (0: none)")] = 10.0,
    pos_rate: Annotated[float, typer.Option(help="POS frames a second (0: none)")] = 4.0,
    start_mission: Annotated[bool, typer.Option(help="START also starts the mission")] = False,
    force_stop: Annotated[bool, typer.Option(help="STOP disarms even in the air")] = False,
    sysid: Annotated[int, typer.Option(help="the bridge's own MAVLink system id")] = 250,
    target_system: Annotated[int, typer.Option(help="the vehicle's system id (0: any)")] = 0,
    log_level: Annotated[str, typer.Option(help="DEBUG, INFO, WARNING")] = "INFO",
) -> None:
    """The thesis's 25-byte text link (ATT, POS down; START, STOP up) on a serial line."""
    from bridges.text_link.bridge import LegacyTextOptions, serve

    logging.basicConfig(level=log_level, format="%(asctime)s legacy_text %(levelname)s %(message)s")
    opts = LegacyTextOptions(
        serial, mavlink, baud, att_rate, pos_rate, start_mission, force_stop, sysid, target_system
    )
    try:
        opts.check()
    except ValueError as exc:
        raise typer.BadParameter(str(exc)) from None
    raise typer.Exit(serve(opts))
