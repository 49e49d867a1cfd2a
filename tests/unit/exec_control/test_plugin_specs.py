"""What the supervisor hands each plug-in process: the vehicle-wide tables only where wanted."""

from __future__ import annotations

import json

from companion.exec_control.config import load_config
from companion.exec_control.supervisor import Supervisor
from tests.support.configs import TICKER, plugin, vehicle_config


def test_only_the_plugins_that_want_them_get_every_parameter_and_setting(tmp_path):
    path = tmp_path / "v.toml"
    path.write_text(
        vehicle_config(
            "v",
            plugin("imu", TICKER, rate_hz=20.0),
            plugin("link", "link.mavlink", endpoints=["udpout://127.0.0.1:9"]),
            plugin("logger", "system.logger"),
        )
    )
    cfg = load_config(path)
    specs = {c.spec.name: json.loads(c._argv_spec) for c in Supervisor(cfg).children}
    declared = {d.name for spec in cfg.plugins for d in spec.params}
    assert len(declared) > 10
    # The link serves the parameters and the logger records them: both get all of them.
    for name in ("link", "logger"):
        assert {d["name"] for d in specs[name]["param_decls"]} == declared
        assert set(specs[name]["plugins"]) == {TICKER, "link.mavlink", "system.logger"}
    # A sensor driver gets its own settings and the vehicle's, not the tables (~1 MB each).
    assert "param_decls" not in specs["imu"] and "plugins" not in specs["imu"]
    assert specs["imu"]["settings"] == {"rate_hz": 20.0}
    assert specs["imu"]["namespace"] == cfg.namespace
