"""Run ``companion sim`` for a test: its own namespace, ports, state and truth file."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from companion.bus.namespace import cleanup_namespace, leftover_files
from tests.support.vehicle import REPO, companion_env, unique_namespace


class SimRun(subprocess.Popen[str]):
    """``companion sim`` with its output in a file: a pipe nobody reads until the end would
    block the simulation once 64 KiB of log lines had piled up (a long flight with a
    warning a second fills it)."""

    def __init__(self, cmd: list[str], log_path: Path, env: dict[str, str]) -> None:
        self.log_path = log_path
        with log_path.open("w") as log:
            super().__init__(cmd, env=env, cwd=REPO, text=True, stdout=log,
                             stderr=subprocess.STDOUT)  # fmt: skip

    def output(self) -> str:
        return self.log_path.read_text(errors="replace")


def start_sim(tmp: Path, link: str, *args: str) -> tuple[SimRun, str, Path]:
    """Start ``companion sim --speed max`` with the given extra options."""
    namespace = unique_namespace("sim")
    truth = tmp / "truth.csv"
    cmd = [
        sys.executable, "-m", "companion", "sim", "--speed", "max", "--namespace", namespace,
        "--state-dir", str(tmp / "state"), "--truth", str(truth), "--link", link, *args,
    ]  # fmt: skip
    return SimRun(cmd, tmp / "sim_output.log", companion_env(namespace)), namespace, truth


def finish(proc: SimRun, namespace: str, timeout_s: float) -> str:
    """Wait for the run to end by itself; return its output; check nothing is left."""
    try:
        proc.wait(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        cleanup_namespace(namespace)
        out = proc.output()
        raise AssertionError(f"companion sim did not finish in {timeout_s} s:\n{out}") from None
    out = proc.output()
    assert proc.returncode == 0, out
    assert leftover_files(namespace) == [], "shared memory left behind"
    return out
