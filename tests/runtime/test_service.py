"""``companion service install``: a unit systemd accepts, whose command runs the vehicle,
stops it cleanly on SIGTERM (exit status 0: not restarted) and closes the flight log
within a second of the signal (a power-loss shutdown keeps the log whole)."""

from __future__ import annotations

import getpass
import logging
import os
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

from companion.messages import CommandId, VehicleCommand
from tests.runtime.test_flight_log import ROWS, imu_ax, make_sensor_log, read_log
from tests.support.configs import plugin, vehicle_config
from tests.support.vehicle import REPO, Vehicle, wait_for

log = logging.getLogger(__name__)
USER = getpass.getuser()


def companion(*args: str | Path) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, "-m", "companion", *map(str, args)]
    return subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=60)


def unit_values(text: str) -> dict[str, list[str]]:
    values: dict[str, list[str]] = {}
    for line in text.splitlines():
        if "=" in line and not line.startswith("#"):
            key, value = line.split("=", 1)
            values.setdefault(key, []).append(value)
    return values


def logged_vehicle(path: Path) -> Path:
    """A logger, and an IMU in the flight group (a replay, stopped as a sensor would be)."""
    samples = path.with_suffix(".csv")
    make_sensor_log(samples)
    logger = plugin("logger", "system.logger", flush_s=1.0)
    imu = plugin("imu", "sensors.replay", group="flight", file=samples, loop=True)
    path.write_text(vehicle_config("svc", logger, imu))
    return path


def test_install_writes_a_unit_that_systemd_verifies_and_uninstall_removes_it(tmp_path):
    config = logged_vehicle(tmp_path / "aircraft.toml")
    root = tmp_path / "root"
    done = companion("service", "install", "-c", config, "--user", USER, "--root", root)
    assert done.returncode == 0, done.stderr
    unit = root / "etc/systemd/system/companion.service"
    v = unit_values(unit.read_text())
    assert v["User"] == [USER] and v["SupplementaryGroups"] == ["dialout"]
    assert v["AmbientCapabilities"] == ["CAP_SYS_NICE"]  # the flight chain's priority
    assert v["Restart"] == ["on-failure"] and v["RestartPreventExitStatus"] == ["2"]
    assert v["KillMode"] == ["mixed"] and v["KillSignal"] == ["SIGTERM"]  # the supervisor's
    assert v["StateDirectory"] == ["companion"]  # /var/lib/companion
    assert "COMPANION_STATE_DIR=%S/companion" in v["Environment"]
    assert v["StandardOutput"] == ["journal"] and v["StandardError"] == ["journal"]
    run = shlex.split(v["ExecStart"][0])
    assert Path(run[0]).is_absolute() and run[-4:-2] == ["--config", str(config.resolve())]
    if shutil.which("systemd-analyze") is None:
        pytest.skip("systemd-analyze is not installed (Debian: apt-get install systemd)")
    verify = subprocess.run(["systemd-analyze", "verify", str(unit)], capture_output=True,
                            text=True, timeout=60)  # fmt: skip
    assert verify.returncode == 0 and verify.stderr == "", verify.stderr

    gone = companion("service", "uninstall", "--root", root)
    assert gone.returncode == 0 and not unit.exists()
    assert companion("service", "uninstall", "--root", root).returncode == 1


def test_a_refused_config_installs_nothing(tmp_path):
    config = tmp_path / "bad.toml"
    config.write_text(vehicle_config("bad", plugin("gps", "sensors.nmea_gsp", device="/dev/x")))
    done = companion("service", "install", "-c", config, "--unit-dir", tmp_path / "units")
    assert done.returncode == 2 and "did you mean 'sensors.nmea_gps'" in done.stderr
    assert not (tmp_path / "units").exists()


def test_an_unknown_user_installs_nothing(tmp_path):
    config = logged_vehicle(tmp_path / "aircraft.toml")
    done = companion("service", "install", "-c", config, "--user", "no_such_user_h4x")
    assert done.returncode == 2 and "no user 'no_such_user_h4x'" in done.stderr
    assert not Path("/etc/systemd/system/companion.service").exists()


def open_by(pid: int, path: Path) -> bool:
    try:
        return any(Path(f.path) == path for f in psutil.Process(pid).open_files())
    except (psutil.NoSuchProcess, psutil.ZombieProcess):
        return False


@pytest.mark.timeout(120)
def test_the_units_command_runs_the_vehicle_and_sigterm_closes_the_log_within_a_second(tmp_path):
    config = logged_vehicle(tmp_path / "aircraft.toml")
    units = tmp_path / "units"
    assert companion("service", "install", "-c", config, "--unit-dir", units).returncode == 0
    exec_start = unit_values((units / "companion.service").read_text())["ExecStart"][0]
    state = tmp_path / "var/lib/companion"  # what systemd's StateDirectory= makes
    vehicle = Vehicle("", tmp_path)  # started by the unit's command line, not the test's
    vehicle.command = shlex.split(exec_start)
    vehicle.extra_env = {"COMPANION_STATE_DIR": str(state)}
    try:
        _armed_log_and_sigterm(vehicle.start(), state / "svc" / vehicle.namespace / "logs")
    finally:
        vehicle.close()


def _armed_log_and_sigterm(vehicle: Vehicle, logs: Path) -> None:
    logger_pid = vehicle.wait_running("logger")
    # Armed only once the logger reads (its first step done), as the flight-log tests do:
    # a logger still subscribing missed the replay's first samples (CI on c4fa64d: the log
    # began at sample 4).
    wait_for(lambda: (r := vehicle.row("logger")) is not None and r.step_p50_us > 0, 30, "logger")
    vehicle.bus.writer("link/commands").publish(
        VehicleCommand(t_us=0, seq=1, command=int(CommandId.START))
    )
    wait_for(lambda: len(imu_ax(read_log(logs))) > ROWS, 30, "an armed log on disk")
    path = sorted(logs.glob("*.ulg"))[-1].resolve()
    assert open_by(logger_pid, path)
    sent = time.monotonic()
    os.kill(vehicle.proc.pid, signal.SIGTERM)
    while open_by(logger_pid, path):
        time.sleep(0.005)
    closed_s = time.monotonic() - sent
    assert vehicle.proc.wait(timeout=5) == 0  # a clean stop: Restart=on-failure leaves it
    log.info("flight log closed %.3f s after SIGTERM", closed_s)
    assert closed_s < 1.0, f"the log was closed {closed_s:.2f} s after SIGTERM"
    ax = imu_ax(read_log(logs))
    assert len(ax) > ROWS and ax == [float(i % ROWS) for i in range(len(ax))]  # whole, in order
