"""The config is the topology: check the channel graph before anything runs.

Refused: a required input nobody produces, a Latest channel with two producers, a
channel name the registry does not know, a device two plug-ins name (each would read part
of its bytes: a path copied into a second entry and not changed). Types cannot disagree:
each channel has one type in companion.messages. ``graph_lines`` is what ``companion
graph`` prints.
"""

from __future__ import annotations

import os
from collections import defaultdict

from companion.exec_control.config import ConfigError, VehicleConfig
from companion.exec_control.plugin_spec import PluginSpec
from companion.messages import CHANNELS
from companion.plugin import Ports
from companion.sensors.serial_port import split_device

# What the execution-control process itself reads and writes.
EXEC_CONTROL = "exec_control"
EXEC_CONTROL_PORTS = Ports(
    optional_inputs=("link/commands", "system/plugin_stats"),
    outputs=("system/health", "link/command_acks"),
)


def _all_ports(cfg: VehicleConfig) -> list[tuple[str, Ports, int | None]]:
    rows = [(spec.name, spec.ports, spec.line) for spec in cfg.plugins]
    return [(EXEC_CONTROL, EXEC_CONTROL_PORTS, None), *rows]


def producers(cfg: VehicleConfig) -> dict[str, list[str]]:
    """Channel → the instances that write it."""
    out: dict[str, list[str]] = defaultdict(list)
    for name, ports, _ in _all_ports(cfg):
        for chan in ports.outputs:
            out[chan].append(name)
    return out


def devices(spec: PluginSpec) -> list[str]:
    """The serial devices (paths, ``sim://`` names) a plug-in opens: its ``device``, and a
    link's ``serial://`` endpoints. A path is taken through its links where it exists (two
    /dev/serial/by-id names of one adapter are one device)."""
    urls = [spec.settings.get("device")]
    urls += [e.split("?")[0] for e in spec.settings.get("endpoints") or () if isinstance(e, str)]
    found = []
    for url in urls:
        if not isinstance(url, str) or not url.startswith(("/", "serial://", "sim://")):
            continue
        path, _ = split_device(url, 0)
        found.append(os.path.realpath(path) if os.path.exists(path) else path)
    return found


def _check_devices(cfg: VehicleConfig) -> None:
    owner: dict[str, str] = {}
    for spec in cfg.plugins:
        for device in devices(spec):
            if device in owner and owner[device] != spec.name:
                raise ConfigError(
                    cfg.path, spec.line, spec.name,
                    f"device {device} is {owner[device]}'s too: one plug-in per device (two"
                    " would each read part of its bytes)",
                )  # fmt: skip
            owner.setdefault(device, spec.name)


def check_topology(cfg: VehicleConfig) -> None:
    """Raise ConfigError (file, line, plug-in) on the first broken connection or device
    named twice."""
    _check_devices(cfg)
    made = producers(cfg)
    for name, ports, line in _all_ports(cfg):
        for chan in (*ports.inputs, *ports.optional_inputs, *ports.outputs):
            if chan not in CHANNELS:
                raise ConfigError(cfg.path, line, name, f"unknown bus channel {chan!r}")
        for chan in ports.inputs:
            if not made.get(chan):
                raise ConfigError(
                    cfg.path, line, name, f"reads {chan!r} but no plug-in in the config writes it"
                )
    for chan, writers in made.items():
        if CHANNELS[chan].pattern == "latest" and len(writers) > 1:
            line = next((s.line for s in cfg.plugins if s.name == writers[-1]), None)
            raise ConfigError(
                cfg.path, line, writers[-1], f"Latest channel {chan!r} has two producers: {writers}"
            )


def graph_lines(cfg: VehicleConfig) -> list[str]:
    """A readable listing of who writes and who reads each channel."""
    readers: dict[str, list[str]] = defaultdict(list)
    for name, ports, _ in _all_ports(cfg):
        for chan in ports.inputs:
            readers[chan].append(name)
        for chan in ports.optional_inputs:
            readers[chan].append(f"{name}?")
    made = producers(cfg)
    lines = []
    for chan in sorted(set(made) | set(readers)):
        info = CHANNELS.get(chan)
        pattern = f"{info.pattern}[{info.depth}]" if info and info.pattern == "queue" else "latest"
        writers = ", ".join(made.get(chan, [])) or "(nobody)"
        takers = ", ".join(readers.get(chan, [])) or "(nobody)"
        lines.append(f"{chan:22} {pattern:10} {writers} -> {takers}")
    return lines
