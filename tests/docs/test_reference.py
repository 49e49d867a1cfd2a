"""The reference pages in docs/reference/ say what the code says."""

from __future__ import annotations

import subprocess
import sys

from tests.support.vehicle import REPO


def test_reference_pages_are_not_stale():
    done = subprocess.run(
        [sys.executable, "docs/gen_reference.py", "--check"],
        cwd=REPO, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    fix = "run `python3 -m uv run python docs/gen_reference.py` and commit docs/reference/"
    assert done.returncode == 0, f"{done.stderr}\n{fix}"
