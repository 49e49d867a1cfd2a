"""Load and check a vehicle config (TOML) before anything starts.

Every refusal is a ConfigError naming the file, the line and the key, with the close
match when a name looks misspelt. The CLI turns it into exit status 2.
"""

from __future__ import annotations

import json
import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from difflib import get_close_matches
from pathlib import Path
from typing import Any

from companion.actuators.airframe import DEFAULT_AIRFRAME, AirframeError, load_airframe
from companion.bus.namespace import default_namespace, validate_namespace
from companion.exec_control.composition import check_processes, process_name
from companion.exec_control.config_locator import KeyPath, line_of, locate
from companion.exec_control.plugin_spec import PluginSpec
from companion.exec_control.priority import NICE_MAX, NICE_MIN
from companion.exec_control.registry import PluginLoadError, load
from companion.plugin import Plugin, Setting

GROUPS = ("core", "flight")
CLOCKS = ("monotonic", "sim")
SIM_REF = "sim://"
STATE_ENV = "COMPANION_STATE_DIR"


class ConfigError(Exception):
    """A config the vehicle refuses to start with."""

    def __init__(self, file: Path, line: int | None, key: str, message: str) -> None:
        self.file, self.line, self.key, self.message = file, line, key, message
        where = f"{file}:{line}" if line else f"{file}"
        super().__init__(f"{where}: {key}: {message}" if key else f"{where}: {message}")


@dataclass(frozen=True)
class VehicleConfig:
    """The whole checked config."""

    path: Path
    name: str
    sysid: int
    namespace: str
    clock: str
    plugins: list[PluginSpec] = field(default_factory=list)
    vehicle: dict[str, Any] = field(default_factory=dict)
    fleet: dict[str, Any] = field(default_factory=dict)  # only `companion sim` reads it


_VEHICLE_KEYS: dict[str, Setting] = {
    "name": Setting(str, "vehicle", "a name for logs and the status table"),
    "sysid": Setting(int, 1, "MAVLink system id", min=1, max=255),
    "namespace": Setting(str, "", "bus namespace (default: $COMPANION_BUS or 'companion')"),
    "clock": Setting(str, "monotonic", "vehicle time base", choices=CLOCKS),
    "airframe": Setting(
        str,
        DEFAULT_AIRFRAME,
        "airframe name (companion/airframes) or TOML path: the controller's gains, the servo"
        " map and the flight log's INFO all come from it (`companion sim --aircraft` replaces it)",
    ),
    "process": Setting(
        str,
        "",
        "the OS process every plug-in without a `process` of its own shares (a small board's"
        " choice: one interpreter, the flight path on one wake-up); empty: one per plug-in",
    ),
    "realtime_priority": Setting(
        int,
        10,
        "SCHED_FIFO priority of the flight chain (the plug-ins at a negative nice) on the"
        " monotonic clock, where the system allows it (CAP_SYS_NICE): woken, it runs before"
        " any normal process; below the kernel's interrupt threads (50). 0: nice values only",
        min=0,
        max=49,
    ),
    "state_dir": Setting(
        str,
        "",
        "where parameters and missions persist"
        " (default $COMPANION_STATE_DIR/NAME/NAMESPACE, or ~/.local/state/companion/..."
        " without it: one vehicle's, never shared)",
    ),
}
# `companion sim` flies this many copies of the vehicle; `companion run` ignores the table.
_FLEET_KEYS: dict[str, Setting] = {
    "count": Setting(int, 1, "vehicles `companion sim` starts", min=1, max=254),
    "spacing_m": Setting(float, 50.0, "vehicle i starts (i-1) * spacing_m east of home", min=0.0),
    "api_port_base": Setting(
        int, 14540, "vehicle i also sends to udpout 127.0.0.1:base+i-1 (0: none)", min=0, max=65535
    ),
}
_TABLES = ["vehicle", "plugins", "fleet"]
_PLUGIN_KEYS = ("name", "plugin", "group", "settings", "process", "nice")
# Settings that belong to the whole vehicle: once a plug-in setting each, now named once in
# [vehicle], so two plug-ins can never disagree (the J3Cub's gains on the Cessna's servos).
_VEHICLE_WIDE = ("airframe",)


class _Checker:
    """Validation helpers bound to one file, so every error carries its position."""

    def __init__(self, path: Path, text: str) -> None:
        self.path = path
        self.lines = locate(text)
        self.sim_refs: Mapping[str, str] | None = None

    def error(self, key_path: KeyPath, message: str) -> ConfigError:
        key = ".".join(str(p) if isinstance(p, str) else f"[{p}]" for p in key_path)
        return ConfigError(
            self.path, line_of(self.lines, key_path), key.replace(".[", "["), message
        )

    def unknown_keys(self, table: dict[str, Any], known: list[str], where: KeyPath) -> None:
        for key in table:
            if key not in known:
                hint = get_close_matches(key, known, n=1)
                tip = f"; did you mean {hint[0]!r}?" if hint else f" (known: {', '.join(known)})"
                raise self.error((*where, key), f"unknown key {key!r}{tip}")

    def values(self, table: dict[str, Any], decl: dict[str, Setting], where: KeyPath) -> dict:
        """Check a table against declared settings; return it with defaults filled in."""
        self.unknown_keys(table, list(decl), where)
        out: dict[str, Any] = {}
        for key, setting in decl.items():
            if key not in table:
                if setting.required:
                    raise self.error((*where, key), f"missing required setting {key!r}")
                out[key] = setting.default
                continue
            out[key] = self.value(table[key], setting, (*where, key))
        return out

    def value(self, value: Any, setting: Setting, where: KeyPath) -> Any:
        want = setting.type
        if want is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if not isinstance(value, want) or (want is int and isinstance(value, bool)):
            got = type(value).__name__
            raise self.error(where, f"expected {want.__name__}, got {got} {value!r}")
        if setting.choices is not None and value not in setting.choices:
            hint = get_close_matches(str(value), [str(c) for c in setting.choices], n=1)
            tip = f"; did you mean {hint[0]!r}?" if hint else ""
            raise self.error(where, f"{value!r} is not one of {list(setting.choices)}{tip}")
        if not isinstance(value, int | float):  # the bounds are a number's
            return value
        if setting.min is not None and value < setting.min:
            raise self.error(where, f"{value!r} is below the minimum {setting.min}")
        if setting.max is not None and value > setting.max:
            raise self.error(where, f"{value!r} is above the maximum {setting.max}")
        return value


def _parse(path: Path) -> tuple[_Checker, dict[str, Any]]:
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise ConfigError(path, None, "", "config file not found") from None
    except OSError as exc:
        raise ConfigError(path, None, "", f"cannot read config: {exc.strerror}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        line = getattr(exc, "lineno", None)
        raise ConfigError(path, line, "", f"not valid TOML: {exc}") from None
    check = _Checker(path, text)
    check.unknown_keys(data, _TABLES, ())
    return check, data


def _table(check: _Checker, data: dict[str, Any], name: str, decl: dict[str, Setting]) -> dict:
    table = data.get(name, {})
    if not isinstance(table, dict):
        raise check.error((name,), f"must be a table: [{name}]")
    return check.values(table, decl, (name,))


def _vehicle_and_fleet(
    check: _Checker, data: dict[str, Any], namespace: str | None = None, airframe: str | None = None
) -> tuple[dict, dict]:
    vehicle = _table(check, data, "vehicle", _VEHICLE_KEYS)
    if vehicle["process"]:
        process_name(check.error, vehicle, ("vehicle",))
    if airframe is not None:
        vehicle["airframe"] = airframe
    try:
        load_airframe(vehicle["airframe"])
    except AirframeError as exc:
        raise check.error(("vehicle", "airframe"), str(exc)) from None
    if not vehicle["state_dir"]:
        # Each bus namespace is one vehicle: two vehicles of one config on one machine
        # must never read each other's mission or parameters.
        ns = namespace or vehicle["namespace"] or default_namespace()
        # A service names its state directory (systemd's StateDirectory=) in the environment.
        base = Path(os.environ.get(STATE_ENV) or "~/.local/state/companion").expanduser()
        vehicle["state_dir"] = str(base / vehicle["name"] / ns)
    return vehicle, _table(check, data, "fleet", _FLEET_KEYS)


def load_sections(
    path: str | Path, namespace: str | None = None
) -> tuple[dict[str, Any], dict[str, Any]]:
    """The checked ``[vehicle]`` and ``[fleet]`` tables, defaults filled in.

    ``companion sim`` needs them before the simulator exists, when the plug-ins' ``sim://``
    settings cannot be resolved yet; the rest of the file is checked when each vehicle starts.
    """
    return _vehicle_and_fleet(*_parse(Path(path)), namespace)


def load_config(
    path: str | Path,
    namespace: str | None = None,
    sim_refs: Mapping[str, str] | None = None,
    airframe: str | None = None,
) -> VehicleConfig:
    """Read, parse and check the config; raise ConfigError on the first problem.

    A setting written ``"sim://NAME"`` takes the value ``sim_refs[NAME]``: the simulator's
    device paths, known only once ``companion sim`` has started it. ``airframe`` replaces
    ``[vehicle] airframe`` (``companion sim --aircraft``: the simulator flies that one).
    """
    path = Path(path)
    check, data = _parse(path)
    check.sim_refs = sim_refs
    vehicle, fleet = _vehicle_and_fleet(check, data, namespace, airframe)
    ns = namespace or vehicle["namespace"] or None
    if ns is not None:
        try:
            validate_namespace(ns)
        except ValueError as exc:
            raise check.error(("vehicle", "namespace"), str(exc)) from None
    specs = _plugin_specs(check, data.get("plugins", []), vehicle)
    return VehicleConfig(
        path=path,
        name=vehicle["name"],
        sysid=vehicle["sysid"],
        namespace=ns or default_namespace(),
        clock=vehicle["clock"],
        plugins=specs,
        vehicle=vehicle,
        fleet=fleet,
    )


def _sim_ref(check: _Checker, value: Any, where: KeyPath) -> Any:
    if not isinstance(value, str) or not value.startswith(SIM_REF):
        return value
    name = value[len(SIM_REF) :]
    if check.sim_refs is None:
        raise check.error(where, f"{value!r} names a simulated device: use `companion sim`")
    if name not in check.sim_refs:
        raise check.error(where, f"the simulator has no {name!r} (it has {sorted(check.sim_refs)})")
    return check.sim_refs[name]


def _plugin_specs(check: _Checker, entries: Any, vehicle: Mapping[str, Any]) -> list[PluginSpec]:
    if not isinstance(entries, list):
        raise check.error(("plugins",), "must be an array of tables: [[plugins]]")
    specs: list[PluginSpec] = []
    seen: set[str] = set()
    for index, entry in enumerate(entries):
        where: KeyPath = ("plugins", index)
        spec = _plugin_spec(check, entry, where, vehicle)
        if spec.name in seen:
            raise check.error((*where, "name"), f"plug-in name {spec.name!r} is used twice")
        seen.add(spec.name)
        specs.append(spec)
    check_processes(check.error, specs)
    return specs


def _plugin_spec(
    check: _Checker, entry: Any, where: KeyPath, vehicle: Mapping[str, Any]
) -> PluginSpec:
    if not isinstance(entry, dict):
        raise check.error(where, "each plug-in must be a table")
    check.unknown_keys(entry, list(_PLUGIN_KEYS), where)
    for key in ("name", "plugin"):
        if key not in entry:
            raise check.error((*where, key), f"missing required key {key!r}")
        if not isinstance(entry[key], str) or not entry[key]:
            raise check.error((*where, key), "expected a non-empty string")
    group = entry.get("group", "core")
    if group not in GROUPS:
        hint = get_close_matches(str(group), GROUPS, n=1)
        tip = f"; did you mean {hint[0]!r}?" if hint else ""
        raise check.error((*where, "group"), f"{group!r} is not one of {list(GROUPS)}{tip}")
    try:
        cls: type[Plugin] = load(entry["plugin"])
    except PluginLoadError as exc:
        raise check.error((*where, "plugin"), str(exc)) from None
    raw_settings = entry.get("settings", {})
    if not isinstance(raw_settings, dict):
        raise check.error((*where, "settings"), "must be a table")
    _refuse_vehicle_wide(check, raw_settings, (*where, "settings"))
    raw_settings = {
        key: _sim_ref(check, value, (*where, "settings", key))
        for key, value in raw_settings.items()
    }
    settings = check.values(raw_settings, cls.settings, (*where, "settings"))
    for problem in cls.validate(settings, vehicle):
        raise check.error((*where, "settings"), problem)
    return PluginSpec(
        name=entry["name"],
        kind=entry["plugin"],
        group=group,
        settings=settings,
        ports=cls.ports(settings),
        line=line_of(check.lines, where),
        params=cls.param_decls(settings, vehicle),
        process=process_name(check.error, entry, where) or vehicle.get("process", ""),
        nice=_nice(check, entry.get("nice", cls.nice), where),
    )


def _nice(check: _Checker, value: Any, where: KeyPath) -> int:
    """The entry's nice value (its class's unless the entry gives one), checked."""
    if isinstance(value, bool) or not isinstance(value, int) or not NICE_MIN <= value <= NICE_MAX:
        raise check.error(
            (*where, "nice"),
            f"nice {value!r} must be a whole number from {NICE_MIN} (first when the CPU is"
            f" short) to {NICE_MAX} (last)",
        )
    return value


def _refuse_vehicle_wide(check: _Checker, settings: dict[str, Any], where: KeyPath) -> None:
    """A vehicle-wide key among a plug-in's settings: refused with the line that replaces it
    (a config written before it moved must not fly two airframes, nor silently one)."""
    for key in _VEHICLE_WIDE:
        if key not in settings:
            continue
        value = settings[key]
        if isinstance(value, str) and value.startswith(SIM_REF):
            line = f"delete it ([vehicle] {key}, default {_VEHICLE_KEYS[key].default!r}; "
            line += "`companion sim --aircraft` chooses the simulated one)"
        else:
            line = f"move it to [vehicle] {key} = {json.dumps(value)}"
        message = f"the {key} is named once, in [vehicle]: {line}"
        raise check.error((*where, key), message)
