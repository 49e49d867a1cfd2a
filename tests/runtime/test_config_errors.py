"""A bad config is refused before anything starts: exit status 2, file, line and key named."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from companion.exec_control.config import ConfigError, load_config
from companion.exec_control.topology import check_topology
from tests.support.configs import RELAY, TICKER, WAITING, plugin, vehicle_config
from tests.support.vehicle import REPO, companion_env

# The line numbers below are those of this layout (see tests.support.configs).
GOOD = vehicle_config(
    "v", plugin("imu", TICKER, rate_hz=20.0), plugin("relay", RELAY, group="flight")
)


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text(textwrap.dedent(text))
    return path


def refuse(tmp_path: Path, text: str) -> ConfigError:
    path = write(tmp_path, text)
    with pytest.raises(ConfigError) as info:
        check_topology(load_config(path))
    assert str(path) in str(info.value)
    return info.value


def test_the_good_config_loads(tmp_path):
    cfg = load_config(write(tmp_path, GOOD))
    check_topology(cfg)
    assert [p.name for p in cfg.plugins] == ["imu", "relay"]
    assert cfg.plugins[0].settings == {"rate_hz": 20.0}
    assert cfg.plugins[1].group == "flight"


def test_unknown_plugin_names_the_line_and_key(tmp_path):
    err = refuse(tmp_path, GOOD.replace("tests.support.plugins:Relay", "sensors.no_such"))
    assert err.key == "plugins[1].plugin" and err.line == 11
    assert "unknown plug-in 'sensors.no_such'" in str(err)


def test_unimportable_module_class(tmp_path):
    err = refuse(tmp_path, GOOD.replace("plugins:Relay", "plugins:Nope"))
    assert "has no Nope" in str(err)


def test_misspelt_setting_suggests_the_close_match(tmp_path):
    err = refuse(tmp_path, GOOD.replace("rate_hz = 20.0", "rate_hx = 20.0"))
    assert err.key == "plugins[0].settings.rate_hx" and err.line == 7
    assert "did you mean 'rate_hz'" in str(err)


def test_misspelt_top_level_and_plugin_keys(tmp_path):
    err = refuse(tmp_path, GOOD.replace('group = "flight"', 'gruop = "flight"'))
    assert err.key == "plugins[1].gruop" and err.line == 12
    assert "did you mean 'group'" in str(err)
    err = refuse(tmp_path, GOOD.replace("[vehicle]", "[vehicel]"))
    assert "did you mean 'vehicle'" in str(err) and err.line == 1


def test_wrong_types_and_values(tmp_path):
    err = refuse(tmp_path, GOOD.replace("rate_hz = 20.0", 'rate_hz = "fast"'))
    assert "expected float, got str" in str(err) and err.line == 7
    err = refuse(tmp_path, GOOD.replace('group = "flight"', 'group = "fligth"'))
    assert "did you mean 'flight'" in str(err)
    err = refuse(tmp_path, GOOD.replace('name = "v"', 'name = "v"\nsysid = 300'))
    assert err.key == "vehicle.sysid" and "above the maximum" in str(err) and err.line == 3


def test_topology_errors(tmp_path):
    err = refuse(
        tmp_path,
        GOOD.replace("tests.support.plugins:Ticker", "tests.support.plugins:Waiting").replace(
            "settings = { rate_hz = 20.0 }", ""
        ),
    )
    assert "reads 'sensors/imu' but no plug-in in the config writes it" in str(err)
    twice = GOOD + "\n" + plugin("relay2", RELAY).toml()
    err = refuse(tmp_path, twice)
    assert "two producers" in str(err) and err.line == 14
    dup = GOOD + "\n" + plugin("imu", WAITING).toml()
    assert "used twice" in str(refuse(tmp_path, dup))


def test_missing_file_and_broken_toml(tmp_path):
    with pytest.raises(ConfigError, match="config file not found"):
        load_config(tmp_path / "absent.toml")
    err = refuse(tmp_path, GOOD.replace('name = "v"', "name = "))
    assert "not valid TOML" in str(err)


def test_cli_exits_with_status_2_and_starts_nothing(tmp_path):
    path = write(tmp_path, GOOD.replace("rate_hz = 20.0", "rate_hx = 20.0"))
    done = subprocess.run(
        [sys.executable, "-m", "companion", "run", "-c", str(path)],
        env=companion_env("cfgerr"),
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert done.returncode == 2
    assert f"{path}:7" in done.stderr and "rate_hx" in done.stderr
    assert "did you mean 'rate_hz'" in done.stderr
    assert "started" not in done.stderr
    missing = subprocess.run(
        [sys.executable, "-m", "companion", "run", "-c", str(tmp_path / "nope.toml")],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert missing.returncode == 2 and "not found" in missing.stderr


def test_registered_short_names_resolve_and_misspellings_get_a_suggestion(tmp_path):
    from companion.exec_control.registry import load, registered

    assert registered()["link.mavlink"] == "companion.plugins.link.mavlink_link:MavlinkLink"
    assert load("link.mavlink").__name__ == "MavlinkLink"
    err = refuse(tmp_path, GOOD.replace("tests.support.plugins:Relay", "link.mavlnk"))
    assert "did you mean 'link.mavlink'" in str(err)


SIM_DEVICE = vehicle_config("v", plugin("gps", "sensors.nmea_gps", device="sim://gps"))


def test_simulated_devices_outside_the_simulator_are_refused(tmp_path):
    err = refuse(tmp_path, SIM_DEVICE)
    assert err.key == "plugins[0].settings.device" and err.line == 7
    assert "companion sim" in str(err)


def test_an_unknown_simulated_device_is_named(tmp_path):
    path = write(tmp_path, SIM_DEVICE.replace("sim://gps", "sim://gsp"))
    with pytest.raises(ConfigError, match=r"no 'gsp'.*\['gps', 'imu'\]"):
        load_config(path, sim_refs={"gps": "/dev/pts/9", "imu": "/dev/pts/8"})
    cfg = load_config(write(tmp_path, SIM_DEVICE), sim_refs={"gps": "/dev/pts/9"})
    assert cfg.plugins[0].settings["device"] == "/dev/pts/9"


def test_the_shipped_sim_config_loads_with_the_bridge_devices():
    devices = ("gps", "compass", "imu", "rc", "range", "battery", "servos")  # the bridge's ptys
    refs = {n: f"/dev/pts/{i}" for i, n in enumerate(devices)}
    cfg = load_config(REPO / "companion/configs/sim.toml", sim_refs=refs, airframe="J3Cub")
    check_topology(cfg)
    servos = next(p for p in cfg.plugins if p.kind == "actuators.minissc")
    assert servos.group == "flight" and cfg.vehicle["airframe"] == "J3Cub"


def test_a_device_two_plugins_name_is_refused(tmp_path):
    """aircraft.toml copied, a second entry's path left as the first's: each plug-in would
    read part of the port's bytes, and neither device would be heard whole."""
    text = (REPO / "companion" / "configs" / "aircraft.toml").read_text()
    gps = "/dev/serial/by-id/usb-Prolific_Technology_Inc._USB-Serial_Controller_D-if00-port0"
    compass = "/dev/serial/by-id/usb-FTDI_FT232R_USB_UART_A9COMPASS-if00-port0"
    assert gps in text and compass in text
    path = tmp_path / "aircraft.toml"
    path.write_text(text.replace(compass, gps))
    with pytest.raises(ConfigError, match=f"device {gps} is gps's too: one plug-in per device"):
        check_topology(load_config(path))
    # The radio's serial endpoint counts too.
    path.write_text(text.replace(
        "serial:///dev/serial/by-id/usb-FTDI_FT231X_USB_UART_DN04RADIO-if00-port0:57600",
        f"serial://{gps}:57600",
    ))  # fmt: skip
    with pytest.raises(ConfigError, match=r"gps: device \S+ is link's too"):
        check_topology(load_config(path))
    path.write_text(text)
    check_topology(load_config(path))  # as shipped: every device once


def test_two_names_of_one_device_are_one_device(tmp_path):
    """Two links to one port (a by-id name and the udev rule's name of one adapter)."""
    port = tmp_path / "ttyUSB0"
    port.write_text("")
    (tmp_path / "by-id-gps").symlink_to(port)
    (tmp_path / "companion-gps").symlink_to(port)
    text = vehicle_config(
        "v",
        plugin("gps", "sensors.nmea_gps", device=str(tmp_path / "by-id-gps")),
        plugin("compass", "sensors.os3000", device=str(tmp_path / "companion-gps")),
    )
    err = refuse(tmp_path, text)
    assert f"compass: device {port} is gps's too" in str(err)
