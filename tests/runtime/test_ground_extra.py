"""The on-board install leaves the ground tools out; their commands say what to install."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from tests.support.vehicle import REPO

# Run the real command line with the ground extra's libraries made unimportable, as they
# are in an on-board install (pip install . without [ground]).
BLOCKED = "import sys\nfor m in {blocked!r}: sys.modules[m] = None\n"
# Every library of the ground extra (pyproject.toml's [ground]).
GROUND = ["jsbsim", "ray", "matplotlib", "pyulog"]
# What filterpy used to pull onto the board (~180 MB), for the gps_compass navigator alone.
NOT_ON_BOARD = ["scipy", "filterpy", "fontTools", "PIL", "kiwisolver"]
RUN_CLI = "from companion.cli import main\nsys.argv = ['companion', *{args!r}]\nmain()\n"


def run_without(blocked: list[str], *args: str) -> subprocess.CompletedProcess[str]:
    code = BLOCKED.format(blocked=blocked) + RUN_CLI.format(args=list(args))
    return subprocess.run(
        [sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=60
    )


def test_sim_without_jsbsim_names_the_extra_to_install() -> None:
    done = run_without(["jsbsim"], "sim", "--duration", "1")
    assert done.returncode == 2
    assert "companion sim needs jsbsim" in done.stderr
    assert "companion[ground]" in done.stderr


def test_campaign_without_ray_names_the_extra_to_install(tmp_path) -> None:
    spec = tmp_path / "c.toml"
    spec.write_text('name = "x"\n')
    done = run_without(["ray"], "campaign", str(spec))
    assert done.returncode == 2
    assert "companion campaign needs ray" in done.stderr


def test_the_vehicle_commands_work_without_the_ground_extra(tmp_path) -> None:
    # The shipped vehicle, on real serial devices instead of the simulator's.
    shipped = (REPO / "companion" / "configs" / "sim.toml").read_text()
    config = tmp_path / "aircraft.toml"
    aircraft = shipped.replace('clock = "sim"', "")
    config.write_text(re.sub(r"sim://(\w+)", r"/dev/tty_\1", aircraft))
    done = run_without(["jsbsim", "ray"], "graph", "--config", str(config))
    assert done.returncode == 0, done.stderr
    assert "nav/state" in done.stdout


def test_replay_of_a_csv_log_works_without_the_ground_extra(tmp_path) -> None:
    log, estimate = tmp_path / "s.csv", tmp_path / "e.csv"
    lines = ["t,kind,ax,ay,az,gx,gy,gz,lat,lon,alt_m,vn,ve,vd,fix,hdop,mx,my,mz,baro_alt_m"]
    lines += [f"{i * 0.02:.2f},imu,0,0,-9.81,0,0,0,,,,,,,,,,,," for i in range(100)]
    log.write_text("\n".join(lines) + "\n")
    done = run_without(GROUND, "replay", str(log), "--out", str(estimate))
    assert done.returncode == 0, done.stderr
    assert estimate.read_text().startswith("t,")


def test_replay_of_a_flight_log_names_the_extra_to_install(tmp_path) -> None:
    flight = tmp_path / "0001_armed.ulg"
    flight.write_bytes(b"ULog")
    done = run_without(GROUND, "replay", str(flight), "--out", str(tmp_path / "e.csv"))
    assert done.returncode == 2
    assert "companion replay FLIGHT.ulg needs pyulog" in done.stderr
    assert "companion[ground]" in done.stderr


def test_the_gps_compass_navigator_runs_without_scipy_or_matplotlib(tmp_path) -> None:
    log, estimate = tmp_path / "s.csv", tmp_path / "e.csv"
    header = "t,kind,ax,ay,az,gx,gy,gz,lat,lon,alt_m,vn,ve,vd,fix,hdop,mx,my,mz,baro_alt_m,"
    lines = [header + "heading_deg,pitch_deg,roll_deg"]
    for i in range(50):  # 10 s northbound at 20 m/s, a fix every 0.2 s
        lat = -37.91 + 20.0 * i * 0.2 / 111_320.0
        lines.append(f"{i * 0.2:.1f},gps,,,,,,,{lat:.8f},145.134,100,20,0,,3,0.8,,,,,,,")
        lines.append(f"{i * 0.2:.1f},compass,,,,,,,,,,,,,,,,,,,5.0,1.0,-2.0")
    log.write_text("\n".join(lines) + "\n")
    blocked = GROUND + NOT_ON_BOARD
    done = run_without(
        blocked, "replay", str(log), "--navigator", "gps_compass", "--out", str(estimate)
    )
    assert done.returncode == 0, done.stderr
    last = estimate.read_text().splitlines()[-1].split(",")
    # Where the aircraft got to after ~9.8 s: ~196 m north of the start, at 20 m/s.
    assert float(last[4]) == pytest.approx(-37.91 + 196.0 / 111_320.0, abs=3e-5)
    assert float(last[7]) == pytest.approx(20.0, abs=0.5)
