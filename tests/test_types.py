"""mypy over the on-board program and the bridges finds nothing ([tool.mypy] in pyproject)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.support.vehicle import REPO

PACKAGES = ("companion", "bridges")


# A first run checks every module and the stubs it reads (about a minute on a busy
# machine); later runs read mypy's cache (.mypy_cache, ignored by git) and check only what
# changed, in seconds.
@pytest.mark.timeout(600)
def test_mypy_finds_no_errors():
    argv = [sys.executable, "-m", "mypy", "--cache-dir", str(REPO / ".mypy_cache"), *PACKAGES]
    done = subprocess.run(argv, cwd=REPO, capture_output=True, text=True, timeout=540)
    assert done.returncode == 0, f"mypy found errors:\n{done.stdout}{done.stderr}"
