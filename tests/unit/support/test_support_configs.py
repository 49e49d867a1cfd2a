"""The config builder the tests and benchmarks share writes what the config loader reads."""

from __future__ import annotations

import tomllib
from pathlib import Path

from companion.exec_control.config import load_config
from tests.support.configs import TICKER, link, plugin, vehicle_config


def test_values_survive_quotes_backslashes_paths_and_lists(tmp_path):
    odd = 'a "quoted" \\ back\\slash, ünï'
    text = vehicle_config(
        "v",
        plugin("imu", TICKER, "flight", rate_hz=20.0, note=odd, on=True, n=3),
        link("udpin://127.0.0.1:1", "serial:///dev/ttyS0:57600"),
        state_dir=tmp_path / "state dir",
    )
    data = tomllib.loads(text)
    assert data["vehicle"] == {"name": "v", "state_dir": str(tmp_path / "state dir")}
    first, second = data["plugins"]
    assert first == {
        "name": "imu",
        "plugin": TICKER,
        "group": "flight",
        "settings": {"rate_hz": 20.0, "note": odd, "on": True, "n": 3},
    }
    assert second["settings"]["endpoints"] == ["udpin://127.0.0.1:1", "serial:///dev/ttyS0:57600"]


def test_a_built_config_passes_the_vehicles_own_checks(tmp_path):
    path = Path(tmp_path / "v.toml")
    path.write_text(vehicle_config("v", plugin("imu", TICKER, rate_hz=20.0), sysid=7))
    cfg = load_config(path)
    assert cfg.vehicle["sysid"] == 7 and [p.name for p in cfg.plugins] == ["imu"]
