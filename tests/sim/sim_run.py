"""Run ``companion sim`` for a test: its own namespace, ports, state and truth file."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from companion.bus import cleanup_namespace, leftover_files
from tests.support.vehicle import REPO, companion_env, unique_namespace


def start_sim(tmp: Path, link: str, *args: str) -> tuple[subprocess.Popen[str], str, Path]:
    """Start ``companion sim --speed max`` with the given extra options."""
    namespace = unique_namespace("sim")
    truth = tmp / "truth.csv"
    cmd = [
        sys.executable, "-m", "companion", "sim", "--speed", "max", "--namespace", namespace,
        "--state-dir", str(tmp / "state"), "--truth", str(truth), "--link", link, *args,
    ]  # fmt: skip
    proc = subprocess.Popen(
        cmd, env=companion_env(namespace), cwd=REPO, text=True,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
    )  # fmt: skip
    return proc, namespace, truth


def finish(proc: subprocess.Popen[str], namespace: str, timeout_s: float) -> str:
    """Wait for the run to end by itself; return its output; check nothing is left."""
    try:
        out, _ = proc.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, _ = proc.communicate()
        cleanup_namespace(namespace)
        raise AssertionError(f"companion sim did not finish in {timeout_s} s:\n{out}") from None
    assert proc.returncode == 0, out
    assert leftover_files(namespace) == [], "shared memory left behind"
    return out
