"""The config check refuses groupings of plug-ins into processes it could not run as meant."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from companion.exec_control.composition import process_group, processes
from companion.exec_control.config import ConfigError, load_config
from tests.support.configs import RELAY, TICKER, WAITING, plugin, vehicle_config


def load(tmp_path: Path, *entries):
    path = tmp_path / "v.toml"
    path.write_text(vehicle_config("v", *entries))
    return load_config(path)


def refused(tmp_path: Path, *entries) -> str:
    with pytest.raises(ConfigError) as info:
        load(tmp_path, *entries)
    return str(info.value)


def test_plugins_naming_one_process_share_it_and_the_others_keep_their_own(tmp_path):
    cfg = load(
        tmp_path,
        replace(plugin("imu", TICKER), process="sensors"),
        plugin("idle", WAITING),
        replace(plugin("relay", RELAY), process="sensors"),
    )
    layout = [(name, [s.name for s in specs]) for name, specs in processes(cfg.plugins)]
    assert layout == [("sensors", ["imu", "relay"]), ("", ["idle"])]


def test_a_process_of_core_and_flight_plugins_is_a_core_process(tmp_path):
    cfg = load(
        tmp_path,
        replace(plugin("imu", TICKER), process="all"),
        replace(plugin("relay", RELAY, group="flight"), process="all"),
    )
    [(name, members)] = processes(cfg.plugins)
    assert (name, process_group(members)) == ("all", "core")


@pytest.mark.parametrize("name", ["", "Core", "1st", "a-very-long-process-name", "exec_control"])
def test_a_process_name_that_is_no_fit_name_is_refused(tmp_path, name):
    message = refused(tmp_path, replace(plugin("imu", TICKER), process=name))
    assert "plugins[0].process" in message and "1-15 characters" in message


def test_a_process_named_after_a_plugin_it_does_not_hold_is_refused(tmp_path):
    message = refused(
        tmp_path,
        replace(plugin("imu", TICKER), process="relay"),
        plugin("relay", RELAY),
    )
    assert "has the name of a plug-in it does not hold" in message


def test_a_process_named_after_its_only_plugin_is_fine(tmp_path):
    cfg = load(tmp_path, replace(plugin("imu", TICKER), process="imu"))
    assert cfg.plugins[0].process == "imu"


def test_the_shipped_composed_config_is_sim_toml_in_one_process():
    import tomllib

    from tests.support.vehicle import REPO

    configs = REPO / "companion" / "configs"
    own = tomllib.loads((configs / "sim.toml").read_text())
    composed = tomllib.loads((configs / "sim_composed.toml").read_text())
    assert composed["vehicle"].pop("process") == "vehicle"
    assert composed == own, "sim_composed.toml must fly the vehicle sim.toml flies"


def test_a_vehicle_wide_process_holds_every_plugin_without_its_own(tmp_path):
    text = vehicle_config(
        "small",
        plugin("imu", TICKER),
        replace(plugin("relay", RELAY), process="apart"),
        plugin("idle", WAITING),
        process="vehicle",
    )
    path = tmp_path / "small.toml"
    path.write_text(text)
    cfg = load_config(path)
    layout = [(name, [s.name for s in specs]) for name, specs in processes(cfg.plugins)]
    assert layout == [("vehicle", ["imu", "idle"]), ("apart", ["relay"])]


def test_a_vehicle_wide_process_that_is_no_fit_name_is_refused(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(vehicle_config("small", plugin("imu", TICKER), process="Vehicle"))
    with pytest.raises(ConfigError) as err:
        load_config(path)
    assert "vehicle.process" in str(err.value) and "1-15 characters" in str(err.value)
