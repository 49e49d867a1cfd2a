"""A vehicle on loopback for a test: ``companion sim`` (JSBSim in lockstep) or
``companion run`` on a bench config (sensors replayed from a log), on its own bus
namespace, state directory and free UDP ports, and the helpers a script's test needs."""

from __future__ import annotations

import signal
import sys
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from companion.flight_log import being_written
from companion.navigation.estimate_csv import read_estimate
from companion.testing.options import VehicleOptions
from companion.testing.processes import (
    LoggedProcess,
    companion_env,
    free_udp_port,
    stop_tree,
    unique_namespace,
)
from companion.testing.watcher import PREARM, VehicleError, Watcher
from mavlink_dialect import companion as d

START_S = 120.0  # wall seconds for a vehicle to answer: a busy machine imports slowly
FORCE_DISARM = 21196  # MAV_CMD_COMPONENT_ARM_DISARM's param 2: disarm even in the air


class TeardownWarning(UserWarning):
    """The vehicle left something behind (it was removed; the vehicle has a bug)."""


@dataclass(frozen=True)
class Ports:
    """The vehicle's UDP endpoints, one per client so that clients never share a peer."""

    watcher: int  # the fixture's helpers (udpin on the vehicle)
    pymavlink: int  # udpin on the vehicle: the client sends first
    mavproxy: int  # udpin on the vehicle
    mavsdk: int  # udpout from the vehicle: MAVSDK listens, as it prefers

    @classmethod
    def free(cls) -> Ports:
        return cls(free_udp_port(), free_udp_port(), free_udp_port(), free_udp_port())

    def links(self, tlog: Path) -> list[str]:
        """The vehicle's endpoint URLs; the watcher's records a .tlog of the whole run."""
        return [
            f"udpin://127.0.0.1:{self.watcher}?tlog={tlog}",
            f"udpin://127.0.0.1:{self.pymavlink}",
            f"udpin://127.0.0.1:{self.mavproxy}",
            f"udpout://127.0.0.1:{self.mavsdk}",
        ]


class LoopbackVehicle:
    """One vehicle process and the helpers. ``kind`` is "sim" or "bench"."""

    def __init__(self, kind: str, folder: Path, options: VehicleOptions | None = None) -> None:
        self.kind = kind
        self.folder = folder
        self.options = options or VehicleOptions()
        self.namespace = unique_namespace(kind)
        self.state_dir = folder / "state"
        self.state_dir.mkdir(parents=True, exist_ok=True)
        self.truth_path = folder / "truth.csv"
        self.tlog_path = folder / "vehicle.tlog"
        self.log_path = folder / "vehicle_output.log"
        self.ports = Ports.free()
        self.proc: LoggedProcess | None = None
        self._watcher: Watcher | None = None

    # -- connection strings ------------------------------------------------------------
    @property
    def pymavlink_url(self) -> str:
        """For ``mavutil.mavlink_connection(url)``: it must send first (a heartbeat)."""
        return f"udpout:127.0.0.1:{self.ports.pymavlink}"

    @property
    def mavsdk_url(self) -> str:
        """For ``System().connect(system_address=url)`` / ``add_any_connection(url)``."""
        return f"udpin://127.0.0.1:{self.ports.mavsdk}"

    @property
    def mavproxy_master(self) -> str:
        """For ``mavproxy.py --master URL``."""
        return f"udpout:127.0.0.1:{self.ports.mavproxy}"

    # -- start and stop ----------------------------------------------------------------
    def start(self, command: list[str], pythonpath: tuple[Path, ...] = ()) -> LoopbackVehicle:
        """Start ``command`` (a ``python -m companion ...`` line) and wait for its heartbeat."""
        env = companion_env(self.namespace, pythonpath)
        self.proc = LoggedProcess(command, self.log_path, env, cwd=self.folder)
        self._watcher = Watcher(self.ports.watcher)
        deadline = time.monotonic() + START_S
        while self.proc.poll() is None and time.monotonic() < deadline:
            try:  # in short waits, so that a vehicle that exits is not waited for
                self._watcher.connect(2.0)
                return self
            except VehicleError:
                continue
        raise VehicleError(f"{self.kind} vehicle never answered:\n{self.output()[-3000:]}")

    def output(self) -> str:
        """What the vehicle printed so far (its log lines)."""
        return self.proc.output() if self.proc is not None else ""

    def close(self) -> None:
        """Stop it as at a terminal (Ctrl-C), kill what is left, empty its /dev/shm."""
        if self._watcher is not None:
            self._watcher.close()
            self._watcher = None
        if self.proc is None:
            return
        left = stop_tree(self.proc, self.namespace, signal.SIGINT)
        if left:
            warnings.warn(f"{self.kind} vehicle {self.namespace}: {left}", TeardownWarning, 2)

    def __enter__(self) -> LoopbackVehicle:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- helpers -----------------------------------------------------------------------
    @property
    def watcher(self) -> Watcher:
        """The fixture's own pymavlink connection (messages, commands, the vehicle clock)."""
        if self._watcher is None:
            raise VehicleError("the vehicle is not running")
        return self._watcher

    def wait_ready(self, timeout_s: float = 180.0) -> None:
        """Until SYS_STATUS says the pre-arm checks pass (QGroundControl's Ready To Fly).
        The vehicle sets that bit only once every device has spoken, so an arm right
        after it is not refused for a device that has not been judged yet."""
        self.watcher.until(
            lambda m: (
                m.get_type() == "SYS_STATUS" and bool(m.onboard_control_sensors_health & PREARM)
            ),
            timeout_s,
            "pre-arm checks passed (SYS_STATUS)",
        )

    def upload_plan(self, plan: str | Path) -> dict[int, int]:
        """Upload a QGroundControl .plan (mission, fence, rally); item count per type."""
        return self.watcher.upload_plan(plan)

    def arm(self, timeout_s: float = 30.0) -> None:
        """Arm (the flight log starts); VehicleError with the vehicle's reason if refused."""
        self.watcher.command(d.MAV_CMD_COMPONENT_ARM_DISARM, 1, timeout_s=timeout_s)

    def arm_and_start(self, timeout_s: float = 30.0) -> None:
        """Arm, then start the mission (MAV_CMD_MISSION_START); VehicleError if refused."""
        self.arm(timeout_s)
        self.watcher.command(d.MAV_CMD_MISSION_START, 0, 0, timeout_s=timeout_s)

    def disarm(self, force: bool = False, timeout_s: float = 30.0) -> list[Path]:
        """Disarm (``force``: in the air too) and wait until the flight's log is closed;
        the flight logs then. VehicleError if refused."""
        cmd = d.MAV_CMD_COMPONENT_ARM_DISARM
        self.watcher.command(cmd, 0, FORCE_DISARM if force else 0, timeout_s=timeout_s)
        w = self.watcher
        w.until(lambda _m: not any(map(being_written, self.flight_logs())), timeout_s,
                "the flight log closed")  # fmt: skip
        return self.flight_logs()

    def run_until_item(self, seq: int, timeout_s: float = 600.0) -> None:
        """Until the mission item ``seq`` is reached (or the mission is past it)."""
        w = self.watcher
        w.drain()

        def past(m: object) -> bool:
            kind = m.get_type()  # type: ignore[attr-defined]
            if kind == "MISSION_ITEM_REACHED":
                return m.seq >= seq  # type: ignore[attr-defined]
            return kind == "MISSION_CURRENT" and m.seq > seq  # type: ignore[attr-defined]

        w.until(past, timeout_s, f"mission item {seq} reached")

    def run_until_mode(self, mode: str, timeout_s: float = 600.0) -> None:
        """Until the vehicle reports ``mode`` (a FlightMode name: "LOITER", "RTL", ...)."""
        w = self.watcher
        w.drain()
        w.until(lambda m: (f := w.mode(m)) is not None and f.name == mode.upper(),
                timeout_s, f"mode {mode}")  # fmt: skip

    def run_until_time(self, t_s: float, timeout_s: float = 600.0) -> float:
        """Until the vehicle clock (the simulated time in a simulation) reaches ``t_s``."""
        w = self.watcher
        w.drain()
        w.until(lambda _m: w.time_boot_s >= t_s, timeout_s, f"vehicle time {t_s:g} s")
        return w.time_boot_s

    def mode(self, timeout_s: float = 10.0) -> str:
        """The vehicle's current mode's name (its next heartbeat)."""
        w = self.watcher
        w.drain()
        return w.until(w.mode, timeout_s, "HEARTBEAT").name

    def truth(self) -> dict[str, np.ndarray]:
        """The simulator's true state so far: columns t (s), roll, pitch, yaw (rad), lat,
        lon (deg), alt (m above sea level), vn, ve, vd (m/s)."""
        if not self.truth_path.exists():
            raise VehicleError(f"no truth file: a {self.kind} vehicle has no simulator")
        return read_estimate(self.truth_path)

    def flight_logs(self) -> list[Path]:
        """The vehicle's flight logs (ULog, one per armed flight) so far, oldest first."""
        return sorted((self.state_dir / "logs").glob("*.ulg"))


def companion_command(*args: str) -> list[str]:
    """``python -m companion ARGS`` with this interpreter."""
    return [sys.executable, "-m", "companion", *args]


def start_sim(
    folder: Path, options: VehicleOptions | None = None, pythonpath: tuple[Path, ...] = ()
) -> LoopbackVehicle:
    """``companion sim`` with ``options`` on free ports; its truth goes to folder/truth.csv."""
    vehicle = LoopbackVehicle("sim", folder, options)
    args = ["sim", "--namespace", vehicle.namespace, "--state-dir", str(vehicle.state_dir),
            "--truth", str(vehicle.truth_path)]  # fmt: skip
    for link in vehicle.ports.links(vehicle.tlog_path):
        args += ["--link", link]
    args += vehicle.options.sim_arguments()
    try:
        return vehicle.start(companion_command(*args), pythonpath)
    except BaseException:
        vehicle.close()
        raise
