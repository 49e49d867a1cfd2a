"""Issue 45: a vehicle is torn down whatever the test did. A user's project (in tmp_path)
has a test that fails with its bench vehicle running, then one that is interrupted (the
pytest process gets SIGINT, as from Ctrl-C, while the vehicle runs). Afterwards no process
names the project's folder and the vehicles' namespaces are gone from /dev/shm."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from companion.bus.namespace import leftover_files
from tests.support.vehicle import wait_for
from tests.testing.test_user_project import _ours_dead, _running_under

PROJECT = """
import time
from pathlib import Path


def test_a_failing_script(bench):
    bench.wait_ready()
    assert bench.mode() == "MISSION", "the user's test fails with the vehicle up"


def test_an_interrupted_script(bench):
    bench.wait_ready()
    Path(__file__).with_name("UP").write_text(bench.namespace)
    time.sleep(600)
"""


@pytest.mark.timeout(600)
def test_a_failed_and_an_interrupted_test_leave_nothing_behind(tmp_path):
    project = tmp_path / "my_scripts"
    project.mkdir()
    (project / "test_scripts.py").write_text(textwrap.dedent(PROJECT))
    before = _ours_dead()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "COMPANION_BUS")}
    cmd = [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", "--timeout", "0",
           "--basetemp", str(tmp_path / "base")]  # fmt: skip
    proc = subprocess.Popen(cmd, cwd=project, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)  # fmt: skip
    try:
        wait_for(lambda: (project / "UP").exists() or proc.poll() is not None, 400, "UP")
        assert proc.poll() is None, proc.communicate()[0]
        proc.send_signal(signal.SIGINT)
        out = proc.communicate(timeout=120)[0]
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert "1 failed" in out and "KeyboardInterrupt" in out, out[-3000:]
    time.sleep(1.0)  # the vehicles' own exit is over by the time pytest returns
    assert _running_under(tmp_path) == []
    assert _ours_dead() - before == set(), "shared memory left behind"
    assert leftover_files((project / "UP").read_text()) == []
