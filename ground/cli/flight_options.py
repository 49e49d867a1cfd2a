"""Option parsers the simulator's commands share (``companion sim``, ``companion hil``)."""

from __future__ import annotations

import typer


def parse_triple(text: str) -> tuple[float, float, float]:
    """``N,E,D`` in m/s (a steady wind)."""
    try:
        n, e, d = (float(v) for v in text.split(","))
    except ValueError:
        raise typer.BadParameter("expected N,E,D in m/s, e.g. 5,0,0") from None
    return n, e, d


def parse_outage(text: str):  # -> Outage, imported when needed
    """``START:SECONDS`` of no GPS fix."""
    from bridges.jsbsim.options import Outage

    try:
        start, seconds = (float(v) for v in text.split(":"))
    except ValueError:
        raise typer.BadParameter("expected START:SECONDS, e.g. 60:30") from None
    return Outage(start, seconds)


def parse_home(text: str | None):  # -> Home, imported when needed
    """``LAT,LON[,GROUND_MSL_M[,HEADING_DEG]]`` of the start; None: the default home."""
    from bridges.jsbsim.conditions import Home

    if text is None:
        return Home()
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if not 2 <= len(values) <= 4:
        raise typer.BadParameter("expected LAT,LON[,GROUND_MSL_M[,HEADING_DEG]]")
    names = ("lat_deg", "lon_deg", "ground_msl_m", "heading_deg")
    return Home(**dict(zip(names, values, strict=False)))
