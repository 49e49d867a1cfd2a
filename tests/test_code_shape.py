"""The tools that keep the code's shape honest: ruff and the import-linter contracts."""

from __future__ import annotations

import shutil
import subprocess
import sys

from tests.support.vehicle import REPO


def run(*argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(argv, cwd=REPO, capture_output=True, text=True, timeout=120)


def test_ruff_finds_nothing():
    done = run(sys.executable, "-m", "ruff", "check", "companion", "ground", "tests", "benchmarks")
    assert done.returncode == 0, done.stdout + done.stderr


def test_import_contracts_hold():
    exe = shutil.which("lint-imports")
    assert exe, "import-linter is a dev dependency"
    done = run(exe)
    assert done.returncode == 0, done.stdout + done.stderr
