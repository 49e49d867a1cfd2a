"""Issue 45: a user's own project, outside this repository, tests its scripts with the
plug-in's fixtures and nothing else (no conftest, no import from tests/), in parallel.

The project is written into tmp_path: a MAVSDK mission script's test (the mission_raw
import of a QGroundControl plan, arm, start, on the simulated c172p) and a pymavlink
ground tool's test (parameters and a mission on the bench vehicle). pytest runs it in a
subprocess with ``-n 2`` (pytest-xdist), the plug-in loaded by its ``pytest11`` entry
point as in any environment with ``companion[testing]``. Both tests must pass, and no
vehicle's process or shared memory may outlive the run.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import psutil
import pytest

from tests.support.vehicle import REPO

SHM = Path("/dev/shm")
OURS = re.compile(r"cmp_(?:sim|bench)(\d+)_")

MISSION_TEST = '''
from pathlib import Path

import pytest
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync

PLAN = Path(__file__).with_name("short_leg.plan")


async def fly(system, plan):
    """The script under test: upload a QGroundControl plan, arm, start."""
    mission = MissionRawAsync(system)
    data = await mission.import_qgroundcontrol_mission(str(plan))
    await mission.upload_mission(data.mission_items)
    await ActionAsync(system).arm()
    await mission.start_mission()


@pytest.mark.asyncio
@pytest.mark.vehicle(airframe="c172p", wind=(0, 3, 0))
async def test_the_script_flies_the_first_leg(sim, mavsdk_system):
    sim.wait_ready()
    await fly(mavsdk_system, PLAN)
    sim.run_until_item(1)
    truth = sim.truth()
    assert truth["alt"][-1] - truth["alt"][0] > 40.0  # it took off and climbed
    assert sim.mode() == "MISSION"
'''

PYMAVLINK_TEST = """
import os

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil


def test_the_tool_sets_a_parameter(bench):
    bench.wait_ready()
    conn = mavutil.mavlink_connection(bench.pymavlink_url, source_system=255)
    conn.mav.heartbeat_send(6, 8, 0, 0, 0)
    assert conn.recv_match(type="HEARTBEAT", blocking=True, timeout=60) is not None
    conn.param_set_send("FS_GCS_TIMEOUT", 9.0)
    msg = conn.recv_match(type="PARAM_VALUE", blocking=True, timeout=30)
    assert msg.param_id == "FS_GCS_TIMEOUT" and msg.param_value == 9.0
    counts = bench.upload_plan(os.path.join(os.path.dirname(__file__), "short_leg.plan"))
    assert counts[0] == 3
    conn.close()
"""


def _ours_dead() -> set[str]:
    """Our fixtures' shared-memory files whose process is gone (left behind)."""
    left = set()
    for path in SHM.glob("cmp_*"):
        m = OURS.match(path.name)
        if m and not psutil.pid_exists(int(m.group(1))):
            left.add(path.name)
    return left


def _running_under(folder: Path) -> list[str]:
    """Processes whose command line names ``folder`` (a vehicle's config or state)."""
    found = []
    for proc in psutil.process_iter(["pid", "cmdline"]):
        cmdline = " ".join(proc.info["cmdline"] or [])
        if str(folder) in cmdline and proc.pid != os.getpid():
            found.append(f"{proc.pid}: {cmdline[:120]}")
    return found


@pytest.mark.timeout(1200)
def test_a_user_project_runs_both_fixtures_in_parallel(tmp_path):
    project = tmp_path / "my_scripts"
    project.mkdir()
    (project / "test_mission_script.py").write_text(textwrap.dedent(MISSION_TEST))
    (project / "test_ground_tool.py").write_text(textwrap.dedent(PYMAVLINK_TEST))
    shutil.copy(REPO / "qgc_plans" / "short_leg.plan", project)
    before = _ours_dead()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "COMPANION_BUS")}
    cmd = [
        sys.executable, "-m", "pytest", "-n", "2", "-p", "no:cacheprovider", "-q",
        "-o", "asyncio_default_fixture_loop_scope=function",
        "--basetemp", str(tmp_path / "base"), "--timeout", "900",
    ]  # fmt: skip
    run = subprocess.run(cmd, cwd=project, env=env, capture_output=True, text=True, timeout=1100)
    out = run.stdout + run.stderr
    assert run.returncode == 0, out[-6000:]
    assert "2 passed" in out, out[-3000:]
    assert _running_under(tmp_path) == []
    assert _ours_dead() - before == set(), "shared memory left behind"
