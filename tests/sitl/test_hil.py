"""Hardware in the loop: ``companion hil`` and ``companion run`` started apart, as on a bench.

The simulator makes its device lines as ptys under a folder (``--ptys``), the vehicle is
started separately with the shipped HIL config pointed at them, on its own clock, and a
MAVSDK script flies a shipped plan over UDP. Nothing else joins the two processes: no bus,
no shared start-up. The flight is real time, so it is scored with a margin for a busy
machine; the same plan in exact lockstep scores 0.5-0.6 m of cross-track RMS.
"""

from __future__ import annotations

import asyncio
import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from companion.bus.namespace import cleanup_namespace, leftover_files
from companion.navigation.estimate_csv import read_estimate
from ground.campaign.scoring import score_track
from tests.protocol.mav_client import free_udp_port
from tests.support.mavsdk_flight import fly_plan
from tests.support.vehicle import REPO, companion_env, unique_namespace

PLAN = REPO / "qgc_plans" / "short_leg.plan"
SHIPPED = REPO / "companion" / "configs" / "hil.toml"


def _vehicle_config(tmp: Path, lines: Path, port: int, namespace: str) -> Path:
    """The shipped HIL config, on this test's lines, state, bus and ground-station port."""
    text = SHIPPED.read_text().replace("/tmp/companion-hil", str(lines))
    text = text.replace(
        '"udpout://127.0.0.1:14550", "udpout://127.0.0.1:14540"', f'"udpout://127.0.0.1:{port}"'
    )
    text = text.replace(
        "[vehicle]\n", f'[vehicle]\nnamespace = "{namespace}"\nstate_dir = "{tmp / "state"}"\n'
    )
    config = tmp / "hil_vehicle.toml"
    config.write_text(text)
    return config


def _start(tmp: Path, name: str, *args: str, env: dict[str, str]) -> subprocess.Popen[str]:
    with (tmp / f"{name}.log").open("w") as out:
        cmd = [sys.executable, "-m", "companion", *args]
        return subprocess.Popen(cmd, cwd=REPO, env=env, text=True, stdout=out, stderr=out)


def _end(proc: subprocess.Popen[str], sig: int) -> int:
    if proc.poll() is None:
        proc.send_signal(sig)
    try:
        return proc.wait(timeout=20)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        raise


@pytest.mark.timeout(400)
def test_a_plan_flown_by_a_vehicle_started_apart_on_the_simulators_lines(tmp_path):
    namespace, port = unique_namespace("hil"), free_udp_port()
    lines, truth = tmp_path / "lines", tmp_path / "truth.csv"
    config = _vehicle_config(tmp_path, lines, port, namespace)
    env = companion_env(namespace)
    sim = _start(tmp_path, "hil", "hil", "--ptys", str(lines), "--truth", str(truth),
                 "--duration", "300", env=env)  # fmt: skip
    vehicle = _start(tmp_path, "vehicle", "run", "--config", str(config), env=env)
    try:
        seen = asyncio.run(fly_plan(port, str(PLAN), 240.0))
    finally:
        sim_status, vehicle_status = _end(sim, signal.SIGINT), _end(vehicle, signal.SIGTERM)
        cleanup_namespace(namespace)
    logs = {n: (tmp_path / f"{n}.log").read_text(errors="replace") for n in ("hil", "vehicle")}
    assert seen["finished"], logs["vehicle"][-3000:]
    assert (sim_status, vehicle_status) == (0, 0), logs
    # The simulator said where its lines were, and took its links away when it ended.
    paths = json.loads(next(ln for ln in logs["hil"].splitlines() if ln.startswith("{")))
    assert paths["gps"] == str(lines / "gps") and paths["servos"] == str(lines / "servos")
    assert list(lines.iterdir()) == []
    assert leftover_files(namespace) == []
    score = score_track(read_estimate(truth), PLAN, "c172p")
    assert score.samples > 300
    assert score.xtrack_rms_m < 4.0, score
    assert score.alt_rms_m < 8.0, score


def test_hil_refuses_a_line_it_cannot_open_and_a_missing_servo_line(tmp_path):
    env = companion_env(unique_namespace("hil"))
    cmd = [sys.executable, "-m", "companion", "hil"]
    missing = str(tmp_path / "no_such_port")
    done = subprocess.run([*cmd, "--gps", "pty:" + str(tmp_path / "gps")], env=env, cwd=REPO,
                          capture_output=True, text=True, timeout=60)  # fmt: skip
    assert done.returncode == 2
    assert "needs the servo line" in done.stderr
    done = subprocess.run([*cmd, "--servos", missing + ":9600"], env=env, cwd=REPO,
                          capture_output=True, text=True, timeout=60)  # fmt: skip
    assert done.returncode != 0
    assert f"servos: cannot open {missing} at 9600 baud" in done.stderr
