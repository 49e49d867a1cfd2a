"""``companion sim``: the simulator bridge and the whole vehicle, started and stopped as one.

The bridge runs in its own process (``python -m bridges.jsbsim``) and makes the ptys; the
vehicle config's ``"sim://NAME"`` settings are then resolved to them and the execution
control runs here, in the main thread. A monitor thread holds the simulation until every
plug-in is up, shows the one-line status, and stops the vehicle when the bridge ends.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import select
import signal
import subprocess
import sys
import threading
import time
import tomllib
from collections.abc import Callable
from pathlib import Path

from bridges.jsbsim.options import BridgeOptions
from companion.bus.namespace import cleanup_namespace, in_use_refusal
from companion.bus.node import BusNode
from companion.control.mission.mission_files import MissionStore
from companion.control.modes import BY_MODE
from companion.exec_control.config import VehicleConfig, load_config
from companion.exec_control.plugin_host import die_with_parent
from companion.exec_control.supervisor import EXIT_BUS_IN_USE, Supervisor
from companion.exec_control.zygote import ForkServer
from companion.messages import FlightMode, PluginState
from ground.sitl.requests import SimRequest

log = logging.getLogger("companion.sim")

READY_TIMEOUT_S = 60.0
BRIDGE_START_S = 30.0
STATUS_PERIOD_S = 0.5
POLL_S = 0.2
QUIET_STATUS_PERIOD_S = 10.0  # when stderr is not a terminal: a log line now and then


class BridgeProcess:
    """The simulator bridge as a child process."""

    def __init__(self, opts: BridgeOptions) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "bridges.jsbsim", opts.to_json()],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            preexec_fn=die_with_parent,
        )
        self.devices = self._read_devices()

    def _read_devices(self) -> dict[str, str]:
        assert self.proc.stdout is not None
        ready, _, _ = select.select([self.proc.stdout], [], [], BRIDGE_START_S)
        line = self.proc.stdout.readline() if ready else ""
        if not line:
            self.stop()
            raise RuntimeError("the simulator bridge did not start (see its log above)")
        return json.loads(line)

    def finished(self, timeout_s: float) -> bool:
        """Whether the simulation reached its end (or the bridge died), waiting at most that."""
        if self.proc.poll() is not None:
            return True
        assert self.proc.stdout is not None
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout_s)
        return bool(ready) and self.proc.stdout.readline() in ("", "done\n")

    def release(self) -> None:
        """Let the simulation begin."""
        assert self.proc.stdin is not None
        try:
            self.proc.stdin.write("run\n")
            self.proc.stdin.flush()
        except BrokenPipeError:
            pass  # it already ended; the monitor sees that

    def stop(self, timeout_s: float = 5.0) -> int:
        """End it (SIGTERM, then SIGKILL) and return its exit status."""
        if self.proc.poll() is None:
            try:
                assert self.proc.stdin is not None
                self.proc.stdin.close()  # "quit": the vehicle no longer reads the lines
                self.proc.wait(1.0)
            except (BrokenPipeError, subprocess.TimeoutExpired):
                pass
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout_s)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        return self.proc.returncode


def vehicle_config(req: SimRequest, opts: BridgeOptions, devices: dict[str, str]) -> VehicleConfig:
    """The sim config with the bridge's ptys, the airframe and the requested links in: the
    airframe JSBSim flies is the vehicle's ([vehicle] airframe), for every plug-in."""
    cfg = load_config(req.config, opts.namespace, sim_refs=devices, airframe=opts.airframe)
    for spec in cfg.plugins:
        if spec.kind == "link.mavlink" and req.links:
            spec.settings["endpoints"] = list(req.links)
        if spec.kind == "system.logger" and opts.exact:
            # One file from boot: a replay then sees every sample the navigator saw.
            spec.settings.update(from_boot=True, split=False, in_step=True)
        if "batch_s" in spec.settings and opts.speed is None:
            # Lockstep: the simulator waits for each driver to read its frame (exact: to
            # publish its sample) before the next step, so a batching driver would hold it.
            spec.settings["batch_s"] = 0.0
        if spec.settings.get("read_on_wake") and opts.speed is None:
            spec.settings["read_on_wake"] = False  # the same: each sample must be read
    if req.state_dir:
        cfg.vehicle["state_dir"] = req.state_dir
    if req.sysid is not None:
        cfg.vehicle["sysid"] = req.sysid  # what the link plug-in reads
        cfg = dataclasses.replace(cfg, sysid=req.sysid)
    if req.plan is not None:
        store = MissionStore(Path(cfg.vehicle["state_dir"]) / "missions")
        for mission_type, items in req.plan.items():
            store.replace(mission_type, items)
        log.info("preloaded %d mission items", len(req.plan.get(0, [])))
    return cfg


class Monitor(threading.Thread):
    """Holds the simulation until the vehicle is up, then reports and watches it."""

    def __init__(self, cfg: VehicleConfig, bridge: BridgeProcess, stop: Callable[[], None]) -> None:
        super().__init__(name="sim-monitor", daemon=True)
        self.cfg, self.bridge, self.stop_vehicle = cfg, bridge, stop
        self.finished = threading.Event()
        self.tty = sys.stderr.isatty()

    def run(self) -> None:
        # A plug-in's death must interrupt the supervisor's wait in the main thread.
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGCHLD})
        bus = BusNode(self.cfg.namespace, "sim_monitor")
        try:
            self._hold_until_ready(bus)
            self.bridge.release()
            self._watch(bus)
        finally:
            bus.close()
            self.stop_vehicle()

    def _hold_until_ready(self, bus: BusNode) -> None:
        health = bus.latest_reader("system/health")
        wanted = {s.name for s in self.cfg.plugins if s.group == "core"}
        deadline = time.monotonic() + READY_TIMEOUT_S
        while time.monotonic() < deadline and not self.finished.is_set():
            table = health.get()
            if table is not None:
                up = {
                    r.name.decode()
                    for r in table.rows()
                    if r.state == PluginState.RUNNING and r.step_p50_us > 0
                }
                if wanted <= up:
                    log.info("vehicle up (%d plug-ins): simulation starts", len(wanted))
                    return
            time.sleep(0.1)
        log.warning("not every plug-in came up within %.0f s; starting anyway", READY_TIMEOUT_S)

    def _watch(self, bus: BusNode) -> None:
        clock, truth = bus.latest_reader("sim/clock"), bus.latest_reader("sim/truth")
        health = bus.latest_reader("system/health")
        status = bus.latest_reader("vehicle/status")
        period = STATUS_PERIOD_S if self.tty else QUIET_STATUS_PERIOD_S
        last = (time.monotonic(), 0)
        while not self.finished.is_set() and not self.bridge.finished(POLL_S):
            now, t_us = time.monotonic(), _t_us(clock.get())
            if now - last[0] < period:
                continue
            factor = (t_us - last[1]) / 1e6 / max(now - last[0], 1e-6)
            last = (now, t_us)
            mode = mode_name(status.get())
            line = status_line(t_us, factor, health.get(), truth.get(), mode)
            if self.tty:
                sys.stderr.write("\r" + line + "\x1b[K")
                sys.stderr.flush()
            else:
                log.info("%s", line)
        if self.tty:
            sys.stderr.write("\n")


def _t_us(sample: object) -> int:
    return 0 if sample is None else int(sample.t_us)


def mode_name(status: object) -> str:
    """The flight mode's name as ground stations show it, from ``vehicle/status``."""
    if status is None:
        return "-"
    try:
        return BY_MODE[FlightMode(status.mode)].name  # type: ignore[attr-defined]
    except (ValueError, KeyError):
        return "-"


def status_line(t_us: int, factor: float, health: object, truth: object, mode: str = "") -> str:
    """``sim 12.3 s  x24.1  ARMED  alt 123 m  air 50.2 m/s  -37.91050 145.13400``.

    A mode name, when given, follows the arm state.
    """
    armed = "ARMED" if health is not None and health.flight_running else "disarmed"
    if mode:
        armed = f"{armed:8s}  {mode:10s}"
    if truth is None:
        return f"sim {t_us / 1e6:7.1f} s  x{factor:5.1f}  {armed}"
    return (
        f"sim {t_us / 1e6:7.1f} s  x{factor:5.1f}  {armed:8s}  alt {truth.alt_agl_m:6.1f} m AGL"
        f"  air {truth.airspeed_m_s:5.1f} m/s  hdg {math.degrees(truth.yaw_rad) % 360:5.1f}"
        f"  {truth.lat_deg:.6f} {truth.lon_deg:.6f}"
    )


def nav_grid_hz(config: Path) -> float:
    """The rate of the config's ``nav.ins_ekf`` states (its fixed grid of vehicle time,
    which lockstep with the control loop follows); 0 when it has none."""
    try:
        with config.open("rb") as f:
            plugins = tomllib.load(f).get("plugins", [])
    except (OSError, tomllib.TOMLDecodeError):
        return 0.0  # load_config reports it properly
    for spec in plugins:
        if isinstance(spec, dict) and spec.get("plugin") == "nav.ins_ekf":
            # The plug-in's own default, not a copy of it (imported only for --exact).
            from companion.plugins.nav.ins_ekf import InsEkfPlugin

            default = InsEkfPlugin.settings["publish_hz"].default
            return float(spec.get("settings", {}).get("publish_hz", default))
    return 0.0


def plugin_kinds(config: Path) -> list[str]:
    """The plug-in kinds a config names (for the fork server to import ahead)."""
    try:
        with config.open("rb") as f:
            plugins = tomllib.load(f).get("plugins", [])
    except (OSError, tomllib.TOMLDecodeError):
        return []  # load_config reports it properly
    return sorted({p["plugin"] for p in plugins if isinstance(p, dict) and "plugin" in p})


def run_sim(req: SimRequest, opts: BridgeOptions, log_level: str = "INFO") -> int:
    """Start the bridge, then the vehicle on its ptys; return when both have stopped."""
    # Lockstep, fast or exact, keeps in step with the navigator's grid (fast: a period
    # behind at most, so a late vehicle process holds the simulation instead of losing data).
    sync_hz = nav_grid_hz(req.config) if opts.speed is None else 0.0
    # An IMU slower than the grid: the navigator publishes at each of its samples instead.
    sync_hz = min(sync_hz, opts.rates.imu_hz)
    if opts.exact and not sync_hz:
        log.warning("--exact: only lockstep (--speed max) with nav.ins_ekf can follow control")
    opts = dataclasses.replace(opts, hold=True, sync_hz=sync_hz)
    # The fork server imports the vehicle's libraries while JSBSim loads its model.
    forker = ForkServer(plugin_kinds(req.config), log_level)
    forker.start()
    # After the fork (this process's iceoryx2 must not be the plug-ins': see the
    # supervisor), before the simulator's clock joins that vehicle's bus.
    if (refusal := in_use_refusal(opts.namespace)) is not None:
        log.error("%s", refusal)
        forker.stop()
        return EXIT_BUS_IN_USE
    try:
        bridge = BridgeProcess(opts)
    except BaseException:
        forker.stop()
        raise
    try:
        cfg = vehicle_config(req, opts, bridge.devices)
        supervisor = Supervisor(cfg, log_level, forker)
        monitor = Monitor(cfg, bridge, lambda: supervisor.request_stop(signal.SIGTERM, None))
        monitor.start()
        code = supervisor.run()
        monitor.finished.set()
        monitor.join(5.0)
    finally:
        forker.stop()  # when the config was refused, the supervisor never ran
        bridge.stop()
        cleanup_namespace(opts.namespace)  # what a killed bridge may have left
    return code
