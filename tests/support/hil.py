"""Hardware in the loop on one machine, for tests and benchmarks: ``companion hil`` making
its lines as ptys under a folder, and ``companion run`` started apart with the shipped HIL
config pointed at them. Nothing joins the two but the ptys and the vehicle's UDP link."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

from companion.bus.namespace import cleanup_namespace
from tests.protocol.mav_client import free_udp_port
from tests.support.vehicle import REPO, companion_env, unique_namespace

SHIPPED = REPO / "companion" / "configs" / "hil.toml"


def hil_vehicle_config(
    tmp: Path, lines: Path, port: int, namespace: str, composed: bool = False
) -> Path:
    """The shipped HIL config, on these lines, state, bus and ground-station port;
    ``composed``: every plug-in in one process (``process = "vehicle"``, as
    ``companion/configs/aircraft.toml`` offers a small board)."""
    text = SHIPPED.read_text().replace("/tmp/companion-hil", str(lines))
    text = text.replace(
        '"udpout://127.0.0.1:14550", "udpout://127.0.0.1:14540"', f'"udpout://127.0.0.1:{port}"'
    )
    process = 'process = "vehicle"\n' if composed else ""
    text = text.replace(
        "[vehicle]\n",
        f'[vehicle]\nnamespace = "{namespace}"\nstate_dir = "{tmp / "state"}"\n{process}',
    )
    config = tmp / "hil_vehicle.toml"
    config.write_text(text)
    return config


class HilRun:
    """The simulator and the vehicle, started apart; MAVLink from the vehicle on ``port``."""

    def __init__(self, tmp: Path, *hil_args: str, composed: bool = False) -> None:
        self.tmp, self.namespace, self.port = tmp, unique_namespace("hil"), free_udp_port()
        self.lines, self.truth = tmp / "lines", tmp / "truth.csv"
        self.started = time.monotonic()  # about when the simulation's time began
        self.config = hil_vehicle_config(tmp, self.lines, self.port, self.namespace, composed)
        self.env = companion_env(self.namespace)
        self.sim = self._start("hil", self.env, "hil", "--ptys", str(self.lines),
                               "--truth", str(self.truth), *hil_args)  # fmt: skip
        self.vehicle = self._start_vehicle("vehicle")

    def restart_vehicle(self, log_name: str = "vehicle_restarted") -> None:
        """Start ``companion run`` again (after it died), as its service would; its output
        goes to ``log_name``."""
        self.vehicle = self._start_vehicle(log_name)

    def _start_vehicle(self, name: str) -> subprocess.Popen[str]:
        # In a session of its own, as systemd starts a service (setsid): on a machine
        # without systemd's cgroups Linux shares the CPU between sessions first
        # (autogroup), and in the test's session a CPU-bound job beside it (the stress
        # mode's hogs) took 3/4 of what its start needed: 7 s from kill -9 to its fork
        # server, 1 s after the kill beside none.
        args = ("run", "--config", str(self.config))
        return self._start(name, self.env, *args, new_session=True)

    def _start(
        self, name: str, env: dict[str, str], *args: str, new_session: bool = False
    ) -> subprocess.Popen[str]:
        with (self.tmp / f"{name}.log").open("w") as out:
            cmd = [sys.executable, "-m", "companion", *args]
            return subprocess.Popen(cmd, cwd=REPO, env=env, text=True, stdout=out, stderr=out,
                                    start_new_session=new_session)  # fmt: skip

    def stop(self) -> tuple[int, int]:
        """End both as a person would (Ctrl-C, a service's SIGTERM); their exit statuses."""
        statuses = (_end(self.sim, signal.SIGINT), _end(self.vehicle, signal.SIGTERM))
        cleanup_namespace(self.namespace)
        return statuses

    def log(self, name: str) -> str:
        """``hil`` or ``vehicle``: what the process printed."""
        return (self.tmp / f"{name}.log").read_text(errors="replace")

    def device_paths(self) -> dict[str, str]:
        """The line of device paths the simulator printed when its lines were up."""
        return json.loads(next(ln for ln in self.log("hil").splitlines() if ln.startswith("{")))


def _end(proc: subprocess.Popen[str], sig: int) -> int:
    if proc.poll() is None:
        proc.send_signal(sig)
    try:
        return proc.wait(timeout=20)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        raise
