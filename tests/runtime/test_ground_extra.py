"""The on-board install leaves the ground tools out; their commands say what to install."""

from __future__ import annotations

import re
import subprocess
import sys

from tests.support.vehicle import REPO

# Run the real command line with the ground extra's libraries made unimportable, as they
# are in an on-board install (pip install . without [ground]).
BLOCKED = "import sys\nfor m in {blocked!r}: sys.modules[m] = None\n"
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
    aircraft = shipped.replace("sim://airframe", "c172p").replace('clock = "sim"', "")
    config.write_text(re.sub(r"sim://(\w+)", r"/dev/tty_\1", aircraft))
    done = run_without(["jsbsim", "ray"], "graph", "--config", str(config))
    assert done.returncode == 0, done.stderr
    assert "nav/state" in done.stdout
