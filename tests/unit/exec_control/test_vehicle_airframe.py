"""One airframe per vehicle: ``[vehicle] airframe``, read by every plug-in; a plug-in's own
``airframe`` setting (as configs had it before) is refused with the line that replaces it."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from companion.actuators import minissc
from companion.actuators.airframe import load_airframe
from companion.exec_control.config import ConfigError, load_config
from companion.exec_control.registry import load
from tests.support.configs import plugin, vehicle_config
from tests.support.vehicle import REPO, companion_env

# The three plug-ins that read the airframe: the controller's gains, the servo map, the log.
READERS = (
    plugin("logger", "system.logger"),
    plugin("control", "control.fixed_wing", group="flight"),
    plugin("servos", "actuators.minissc", group="flight", device="/dev/ttyS9"),
)


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "vehicle.toml"
    path.write_text(textwrap.dedent(text))
    return path


def refused(path: Path, **kwargs) -> ConfigError:
    with pytest.raises(ConfigError) as info:
        load_config(path, **kwargs)
    return info.value


def airframe_seen(cfg) -> dict[str, str]:
    """Which airframe each reader flies: the controller's by its parameters' origin, the
    servo card's by the neutral frames it is sent, the log's by the vehicle table."""
    specs = {spec.name: spec for spec in cfg.plugins}
    origins = {d.origin for d in specs["control"].params} - {"default"}
    cls = load("actuators.minissc")
    (probe,) = cls.probe(specs["servos"].settings, cfg.vehicle)
    by_frames = [
        name
        for name in ("c172p", "J3Cub")
        if probe.neutral
        == b"".join(minissc.frame(c.servo, c.safe) for c in load_airframe(name).channels)
    ]
    (origin,) = origins
    return {"control": origin, "servos": by_frames[0], "logger": cfg.vehicle["airframe"]}


def test_every_reader_flies_the_vehicle_airframe(tmp_path):
    cub = load_config(write(tmp_path, vehicle_config("v", *READERS, airframe="J3Cub")))
    assert airframe_seen(cub) == {
        "control": "airframe J3Cub.toml", "servos": "J3Cub", "logger": "J3Cub"
    }  # fmt: skip
    params = {d.name: d.default for d in next(s for s in cub.plugins if s.name == "control").params}
    assert params["AIRSPEED_CRUISE"] == 26.0  # the Cub's, not the Cessna's 36
    # Named nowhere: the Cessna, as the plug-ins' settings defaulted to before.
    cessna = load_config(write(tmp_path, vehicle_config("v", *READERS)))
    assert airframe_seen(cessna) == {
        "control": "airframe c172p.toml", "servos": "c172p", "logger": "c172p"
    }  # fmt: skip
    # `companion sim --aircraft c172p` on the Cub's config: all three change together.
    path = write(tmp_path, vehicle_config("v", *READERS, airframe="J3Cub"))
    assert set(airframe_seen(load_config(path, airframe="c172p")).values()) == {
        "airframe c172p.toml", "c172p"
    }  # fmt: skip


@pytest.mark.parametrize("reader", range(len(READERS)))
def test_a_plugin_level_airframe_is_refused_with_the_line_to_change(tmp_path, reader):
    old = list(READERS)
    entry = old[reader]
    old[reader] = plugin(entry.name, entry.kind, entry.group, **entry.settings, airframe="J3Cub")
    path = write(tmp_path, vehicle_config("v", *old))
    err = refused(path)
    assert err.key == f"plugins[{reader}].settings.airframe"
    lines = path.read_text().splitlines()
    assert err.line == next(n for n, line in enumerate(lines, 1) if "airframe" in line)
    assert str(err).endswith(
        'the airframe is named once, in [vehicle]: move it to [vehicle] airframe = "J3Cub"'
    )


def test_the_simulators_old_airframe_reference_says_to_delete_it(tmp_path):
    old = plugin(
        "servos", "actuators.minissc", "flight", device="sim://servos", airframe="sim://airframe"
    )
    err = refused(write(tmp_path, vehicle_config("v", old)), sim_refs={"servos": "/dev/pts/3"})
    assert err.key == "plugins[0].settings.airframe"
    assert "delete it" in str(err) and "companion sim --aircraft" in str(err)


def test_an_airframe_that_does_not_load_is_refused_at_its_line(tmp_path):
    err = refused(write(tmp_path, vehicle_config("v", *READERS, airframe="J3Club")))
    assert err.key == "vehicle.airframe" and err.line == 3
    assert "no such airframe file" in str(err) and "J3Cub" in str(err)  # the shipped ones


def test_companion_run_refuses_the_old_aircraft_config_before_starting(tmp_path):
    """The shipped aircraft config as it was written before: named three times."""
    text = (REPO / "companion" / "configs" / "aircraft.toml").read_text()
    text = text.replace('airframe = "J3Cub"\n', "", 1)
    old = text.replace(
        'plugin = "system.logger"\n',
        'plugin = "system.logger"\nsettings = { airframe = "J3Cub" }\n',
    )
    path = write(tmp_path, old)
    line = old.splitlines().index('settings = { airframe = "J3Cub" }') + 1
    done = subprocess.run(
        [sys.executable, "-m", "companion", "graph", "-c", str(path)],
        env=companion_env("airframe_cfg"), cwd=REPO, capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert done.returncode == 2, done.stdout + done.stderr
    assert f"{path}:{line}" in done.stderr
    assert 'move it to [vehicle] airframe = "J3Cub"' in done.stderr.replace("\n", "")
