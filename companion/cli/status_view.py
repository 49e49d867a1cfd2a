"""Read the health table from the bus and render it (rich table or JSON)."""

from __future__ import annotations

import math
from typing import Any

from rich.table import Table

from companion.bus.namespace import cleanup_namespace
from companion.bus.node import BusNode
from companion.messages import PluginState, SystemHealth


def read_health(namespace: str, timeout_s: float) -> SystemHealth | None:
    """The newest health table of the vehicle on that namespace, or None if silent."""
    with BusNode(namespace, "status") as bus:
        reader = bus.latest_reader("system/health")
        latest = reader.get()
        if latest is None:
            latest = reader.wait(timeout_s)
    cleanup_namespace(namespace)  # no-op while a vehicle runs; tidies an empty namespace
    return latest


def health_dict(msg: SystemHealth) -> dict[str, Any]:
    """The table as plain data (what ``companion status --json`` prints)."""
    rows = []
    for row in msg.rows():
        item = row.as_dict()
        item["state"] = PluginState(row.state).name.lower()
        for key in ("step_p50_us", "step_p99_us"):
            value = item[key]
            if isinstance(value, float) and math.isnan(value):
                item[key] = None
        rows.append(item)
    return {
        "t_us": msg.t_us,
        "supervisor_pid": msg.supervisor_pid,
        "flight_running": bool(msg.flight_running),
        "plugins": rows,
    }


def _us(value: float | None) -> str:
    return "-" if value is None else f"{value:.0f}"


def health_table(msg: SystemHealth) -> Table:
    """A rich table of the plug-ins' state, pid, restarts, CPU and counters."""
    data = health_dict(msg)
    armed = "flight group RUNNING" if data["flight_running"] else "flight group stopped"
    table = Table(title=f"companion (supervisor pid {data['supervisor_pid']}, {armed})")
    cols = ("plug-in", "kind", "group", "process", "state", "pid", "restarts", "CPU %", "RSS MiB")
    for col in cols:
        table.add_column(col, justify="right" if col[0].isupper() or col == "pid" else "left")
    for col in ("bytes in", "ok", "bad", "refused", "dropped", "step p50 µs", "p99 µs"):
        table.add_column(col, justify="right")
    for p in data["plugins"]:
        table.add_row(
            p["name"],
            p["kind"],
            p["group"],
            p["process"] or "(own)",  # the OS process it shares, set by the config
            p["state"],
            str(p["pid"] or "-"),
            str(p["restarts"]),
            f"{p['cpu_pct']:.1f}",
            f"{p['rss_kib'] / 1024:.0f}",
            str(p["bytes_in"]),  # from the plug-in's device: 0 with frames 0 is a silent one
            str(p["frames_ok"]),
            str(p["frames_bad"]),
            str(p["refused"]),
            str(p["dropped"]),
            _us(p["step_p50_us"]),
            _us(p["step_p99_us"]),
        )
    return table
