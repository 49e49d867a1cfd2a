"""Processes a test starts: their own bus namespace, free ports, output in a file, and a
teardown that leaves nothing running and nothing in /dev/shm."""

from __future__ import annotations

import contextlib
import itertools
import logging
import os
import random
import signal
import socket
import subprocess
from collections.abc import Sequence
from pathlib import Path

import psutil

from companion.bus.namespace import cleanup_namespace, leftover_files

log = logging.getLogger(__name__)
_counter = itertools.count()


def unique_namespace(tag: str = "t") -> str:
    """A bus namespace no other test uses: the pid tells pytest-xdist's workers (and two
    sessions on one machine) apart, the counter the vehicles of one process."""
    return f"{tag}{os.getpid()}_{next(_counter)}"


# Ports are handed out below the kernel's ephemeral range (32768-60999 on Linux): a port the
# kernel picked could go, the moment its finder let it go, to any socket bound to port 0 (a
# ground station's, another test's), and the vehicle then started on it found it taken (a
# link's "Address already in use" in CI, 2026-12-05). Each pytest-xdist worker draws from
# its own slice, so two workers never race for one either.
PORT_RANGE = (20000, 32000)


def free_udp_port() -> int:
    """A loopback UDP port nobody on this machine holds now, outside the ports the kernel
    gives sockets bound to port 0, from this test worker's own slice of them."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")[2:]
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1") or 1)
    span = (PORT_RANGE[1] - PORT_RANGE[0]) // max(workers, 1)
    low = PORT_RANGE[0] + (int(worker) % max(workers, 1) if worker.isdigit() else 0) * span
    for _ in range(1000):
        port = random.randrange(low, low + span)
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
            try:
                sock.bind(("127.0.0.1", port))
            except OSError:
                continue  # held: draw again
            return port
    raise OSError(f"no free UDP port in {low}..{low + span - 1}")


def companion_env(namespace: str, pythonpath: Sequence[Path] = ()) -> dict[str, str]:
    """This environment with the vehicle's bus namespace (and more import paths first)."""
    env = dict(os.environ)
    env["COMPANION_BUS"] = namespace
    if pythonpath:
        env["PYTHONPATH"] = os.pathsep.join([*map(str, pythonpath), env.get("PYTHONPATH", "")])
    return env


class LoggedProcess(subprocess.Popen[str]):
    """A process whose output goes to a file: a pipe nobody reads until the end would
    block it once 64 KiB of log lines had piled up (a long flight with a warning a second
    fills it)."""

    def __init__(
        self, cmd: list[str], log_path: Path, env: dict[str, str], cwd: Path | None = None
    ) -> None:
        self.log_path = log_path
        with log_path.open("w") as out:
            super().__init__(cmd, env=env, cwd=cwd, text=True, stdout=out,
                             stderr=subprocess.STDOUT)  # fmt: skip

    def output(self) -> str:
        """What it printed so far."""
        return self.log_path.read_text(errors="replace") if self.log_path.exists() else ""

    def tree(self) -> list[int]:
        """Its pid and its descendants' (the vehicle's plug-ins, the simulator)."""
        try:
            kids = psutil.Process(self.pid).children(recursive=True)
        except psutil.NoSuchProcess:
            return []
        return [self.pid, *(k.pid for k in kids)]


def stop_tree(
    proc: LoggedProcess, namespace: str, sig: int = signal.SIGINT, timeout_s: float = 30.0
) -> list[str]:
    """Stop ``proc`` as at a terminal (``sig``), kill whatever of its tree is left after
    ``timeout_s``, remove the namespace's shared memory. Returns what was left behind or
    went wrong (empty after a clean stop: exit status 0, nothing running, nothing in
    /dev/shm): the caller decides whether that fails the test."""
    pids = proc.tree()  # read first: the children are orphaned once the parent is gone
    left: list[str] = []
    if proc.poll() is None:
        proc.send_signal(sig)
        try:
            proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            left.append(f"pid {proc.pid} still running {timeout_s} s after signal {sig}")
    for pid in pids:
        with contextlib.suppress(psutil.NoSuchProcess, ProcessLookupError):
            if psutil.Process(pid).is_running():
                if pid != proc.pid:
                    left.append(f"child pid {pid} outlived the vehicle")
                os.kill(pid, signal.SIGKILL)
    with contextlib.suppress(subprocess.TimeoutExpired):
        proc.wait(timeout=5.0)
    if not left and proc.returncode not in (0, None):  # a clean stop exits 0, also on sig
        left.append(f"exit status {proc.returncode} (its output: {proc.log_path})")
    shm = leftover_files(namespace)
    if shm:
        left.append(f"shared memory left behind: {[p.name for p in shm]}")
    cleanup_namespace(namespace)
    return left
