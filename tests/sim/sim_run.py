"""Run ``companion sim`` for a test: its own namespace, ports, state and truth file.

The process, namespace and teardown code is the pytest plug-in's (companion.testing);
this keeps the API the flight tests were written against. New tests can take the
plug-in's ``sim`` fixture instead."""

from __future__ import annotations

import asyncio
import contextlib
import signal
import subprocess
import sys
from collections.abc import Awaitable, Callable, Iterator
from pathlib import Path
from typing import TypeVar

from companion.bus.namespace import leftover_files
from companion.testing.processes import LoggedProcess, free_udp_port, stop_tree
from tests.support.vehicle import REPO, companion_env, unique_namespace

T = TypeVar("T")


class SimRun(LoggedProcess):
    """``companion sim`` with its output in a file (the plug-in's LoggedProcess, run from
    the repository so that the tests' own plug-in modules import)."""

    def __init__(self, cmd: list[str], log_path: Path, env: dict[str, str]) -> None:
        super().__init__(cmd, log_path, env, cwd=REPO)


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
        stop_tree(proc, namespace, signal.SIGKILL)  # the whole tree, not only its top
        out = proc.output()
        raise AssertionError(f"companion sim did not finish in {timeout_s} s:\n{out}") from None
    out = proc.output()
    assert proc.returncode == 0, out
    assert leftover_files(namespace) == [], "shared memory left behind"
    return out


@contextlib.contextmanager
def sim_running(tmp: Path, *args: str) -> Iterator[tuple[int, SimRun, Path]]:
    """``companion sim --speed max`` with ``args``, a ground station's link on a free port:
    (that port, the process, the truth file). Stopped as at a terminal when the block ends,
    and nothing may be left behind. No simulated-time budget: disarmed, the simulation runs
    as fast as the machine lets it, so a budget is spent by wall time (a loaded machine ran
    one out before the aircraft was over its point); the test's timeout bounds the run."""
    port = free_udp_port()
    proc, namespace, truth_path = start_sim(tmp, f"udpout://127.0.0.1:{port}", *args)
    try:
        yield port, proc, truth_path
    finally:
        left = stop_tree(proc, namespace, signal.SIGINT)
    assert left == [], f"{left}\n{proc.output()[-3000:]}"


def with_sim(
    tmp: Path, script: Callable[[int], Awaitable[T]], aircraft: str = "c172p"
) -> tuple[T, str, Path]:
    """Run the asyncio ``script(port)`` (a ground station hearing the vehicle on udpin
    ``port``) against ``companion sim`` (``sim_running``); its result, the vehicle's output
    and the truth file."""
    with sim_running(tmp, "--aircraft", aircraft) as (port, proc, truth_path):
        result = asyncio.run(script(port))
    return result, proc.output(), truth_path
