"""The shipped configs for the real aircraft: each passes `companion graph` as shipped,
names its devices by a path that survives a reboot, and signs what the radio carries."""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib

import pytest

from companion.exec_control.config import load_config
from tests.support.vehicle import REPO

CONFIGS = REPO / "companion/configs"
HARDWARE = ("aircraft.toml", "bench.toml")


def companion(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, "-m", "companion", *args]
    return subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=60, env=env)


@pytest.mark.parametrize("name", HARDWARE)
def test_the_config_passes_companion_graph(name):
    done = companion("graph", "--config", str(CONFIGS / name))
    assert done.returncode == 0, done.stderr
    plugins = tomllib.loads((CONFIGS / name).read_text())["plugins"]
    for entry in plugins:  # every plug-in is in the printed graph
        assert re.search(rf"^  {entry['name']} +{re.escape(entry['plugin'])} ", done.stdout, re.M)


@pytest.mark.parametrize("name", HARDWARE)
def test_devices_are_named_by_id(name):
    cfg = load_config(CONFIGS / name)
    devices = [s.settings["device"] for s in cfg.plugins if "device" in s.settings]
    radios = [u for s in cfg.plugins for u in s.settings.get("endpoints", ()) if "serial" in u]
    assert devices
    for path in devices + [u.removeprefix("serial://") for u in radios]:
        assert path.startswith("/dev/serial/by-id/usb-"), path


def test_the_aircraft_flies_what_the_thesis_flew_and_its_radio_requires_signing():
    cfg = load_config(CONFIGS / "aircraft.toml")
    kinds = {s.name: s for s in cfg.plugins}
    assert kinds["gps"].kind == "sensors.nmea_gps" and kinds["gps"].settings["baud"] == 4800
    assert kinds["compass"].kind == "sensors.os3000"
    assert kinds["imu"].kind == "sensors.serial_imu"
    assert kinds["servos"].kind == "actuators.minissc" and kinds["servos"].group == "flight"
    radio, wifi = kinds["link"].settings["endpoints"]
    assert radio.endswith(":57600?signing=required") and wifi.startswith("udpout://")
    assert kinds["link"].settings["signing_key_file"]


def test_the_bench_config_moves_nothing():
    cfg = load_config(CONFIGS / "bench.toml")
    assert {s.kind.split(".")[0] for s in cfg.plugins} == {"link", "sensors", "nav"}


def test_state_goes_where_the_service_says(tmp_path, monkeypatch):
    monkeypatch.setenv("COMPANION_STATE_DIR", str(tmp_path))
    cfg = load_config(CONFIGS / "bench.toml", namespace="benchns")
    assert cfg.vehicle["state_dir"] == str(tmp_path / "bench" / "benchns")


def test_udev_rules_name_every_aircraft_device():
    rules = (CONFIGS / "99-companion.rules").read_text().splitlines()
    rules = [r for r in rules if r.strip() and not r.startswith("#")]
    names = {re.search(r'SYMLINK\+="companion/(\w+)"', r).group(1) for r in rules}
    assert names == {"gps", "compass", "imu", "servos", "radio"}
    for rule in rules:
        assert rule.startswith('SUBSYSTEM=="tty"') and 'GROUP="dialout"' in rule
        # udev's syntax: comma-separated KEY==value matches and KEY+=/= assignments
        for part in rule.split(", "):
            assert re.fullmatch(r'[A-Z_]+(\{\w+\})?(==|\+=|=)"[^"]*"', part), part
