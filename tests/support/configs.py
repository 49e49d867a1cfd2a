"""Vehicle configs for tests and benchmarks, built here instead of copied as TOML text.

``vehicle_config(name, plugin(...), ...)`` renders the file ``companion run -c`` reads:
the ``[vehicle]`` table, then one ``[[plugins]]`` table per plug-in (name, plugin, group,
settings as an inline table), a blank line between tables. Tests of the config checker
count on that layout for the line numbers in its messages.

The vehicles several test files (and the link benchmark) fly are below: a link on an
endpoint with a known navigation solution, with or without the commander.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

TICKER = "tests.support.plugins:Ticker"
RELAY = "tests.support.plugins:Relay"
WAITING = "tests.support.plugins:Waiting"
FAKE_NAV = "tests.support.plugins:FakeNav"
FAKE_GPS = "tests.support.plugins:FakeGps"
CRASH_AFTER = "tests.support.plugins:CrashAfter"
PUBLISH_ONCE = "tests.support.plugins:PublishOnce"
FAKE_APPROACH = "tests.support.plugins:FakeApproach"


@dataclass(frozen=True)
class PluginEntry:
    """One ``[[plugins]]`` table."""

    name: str
    kind: str  # the ``plugin`` key: a registered name or module:Class
    group: str | None = None
    settings: dict[str, Any] = field(default_factory=dict)
    process: str | None = None  # the OS process it shares with others
    nice: int | None = None  # the scheduling priority it asks for

    def toml(self) -> str:
        """The table as TOML lines."""
        lines = ["[[plugins]]", f"name = {_value(self.name)}", f"plugin = {_value(self.kind)}"]
        if self.group is not None:
            lines.append(f"group = {_value(self.group)}")
        if self.process is not None:
            lines.append(f"process = {_value(self.process)}")
        if self.nice is not None:
            lines.append(f"nice = {_value(self.nice)}")
        if self.settings:
            lines.append(f"settings = {_value(self.settings)}")
        return "\n".join(lines) + "\n"


def plugin(name: str, kind: str, group: str | None = None, **settings: Any) -> PluginEntry:
    """A plug-in instance: ``plugin("imu", TICKER, rate_hz=50.0)``."""
    return PluginEntry(name, kind, group, settings)


def vehicle_config(name: str, *plugins: PluginEntry, **vehicle: Any) -> str:
    """The config file's text: ``[vehicle]`` with ``name`` and the other keys given."""
    head = "\n".join(
        ["[vehicle]", *(f"{key} = {_value(v)}" for key, v in {"name": name, **vehicle}.items())]
    )
    return "\n".join([head + "\n", *(p.toml() for p in plugins)])


def _value(value: Any) -> str:
    """A TOML value: strings (and paths) quoted, numbers, booleans, lists, inline tables."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(value)
    if isinstance(value, str | Path):
        return json.dumps(str(value))  # a JSON string is a TOML basic string
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_value(v)}" for k, v in value.items()) + " }"
    raise TypeError(f"no TOML for {value!r}")


def pipeline(relay_group: str = "core") -> str:
    """IMU ticker → relay → nav/state, plus a plug-in that only waits."""
    return vehicle_config(
        "pipeline",
        plugin("imu", TICKER, rate_hz=50.0),
        plugin("relay", RELAY, group=relay_group),
        plugin("idle", WAITING),
    )


def link(*endpoints: str, **settings: Any) -> PluginEntry:
    """The MAVLink link plug-in on these endpoints."""
    return plugin("link", "link.mavlink", endpoints=list(endpoints), **settings)


def flight_group() -> PluginEntry:
    """A stand-in for the flight group, so commands that start it have something to start."""
    return plugin("flight", WAITING, group="flight")


def link_vehicle(endpoint: str, state: str | Path) -> str:
    """A link, a known navigation solution, an IMU ticking, a flight group; no commander."""
    return vehicle_config(
        "linktest",
        link(endpoint),
        plugin("nav", FAKE_NAV),
        plugin("imu", TICKER),
        plugin("relay_in_flight", WAITING, group="flight"),
        sysid=1,
        state_dir=state,
    )


def client_vehicle(
    endpoint: str,
    state: str | Path,
    extra: tuple[PluginEntry, ...] = (),
    flight: PluginEntry | None = None,
    name: str = "client",
    autopilot: str = "px4",
    **vehicle: Any,
) -> str:
    """A link on ``endpoint``, a known navigation solution, ``extra``, the commander, and
    ``flight`` in the flight group (a stand-in by default); ``vehicle``: more ``[vehicle]``
    keys (``airframe="J3Cub"``)."""
    return vehicle_config(
        name,
        link(endpoint, autopilot=autopilot),
        plugin("nav", FAKE_NAV),
        plugin("gps", FAKE_GPS),  # a 3-D fix: the pre-arm checks pass
        *extra,
        plugin("commander", "vehicle.commander"),
        flight or flight_group(),
        state_dir=state,
        **vehicle,
    )


def shipped_config(name: str, directory: Path) -> Path:
    """``companion/configs/NAME.toml`` copied into ``directory``, its state kept there
    (``state/``): a shipped vehicle whose parameters a test may change."""
    shipped = Path(__file__).resolve().parents[2] / "companion" / "configs" / f"{name}.toml"
    state = f"[vehicle]\nstate_dir = {json.dumps(str(directory / 'state'))}\n"
    config = directory / f"{name}.toml"
    config.write_text(shipped.read_text().replace("[vehicle]\n", state, 1))
    return config
