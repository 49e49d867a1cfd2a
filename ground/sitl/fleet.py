"""Several complete simulated vehicles at once (``companion sim --count N``).

Each vehicle is a ``companion sim --count 1`` child process with everything of its own:
MAVLink system id i, bus namespace ``<namespace>_v<i>``, simulator bridge, home
``(i-1) * spacing_m`` east of the fleet's home, state dir ``<state_dir>/v<i>`` (its log is
``sim.log`` there) and truth file ``<stem>_v<i>.csv``. All of them send to the shared
ground-station endpoints, and each to its own API port as PX4's multi-vehicle SITL does.
Separate processes, rather than threads of one, keep one vehicle's crash or stall from
touching the others, and run the very code a single ``companion sim`` runs.

This process only starts them, shows one status line per vehicle (read from each
vehicle's bus), forwards SIGINT/SIGTERM, and cleans every namespace when they are gone.
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import psutil

from bridges.jsbsim.conditions import Home
from companion.bus.namespace import cleanup_namespace, validate_namespace
from companion.bus.node import BusNode
from companion.exec_control.plugin_host import die_with_parent
from companion.geodesy import LocalFrame
from ground.sitl.requests import FleetRequest
from ground.sitl.session import mode_name, status_line

log = logging.getLogger("ground.sitl.fleet")

POLL_S = 0.25
STATUS_PERIOD_S = 0.5
QUIET_STATUS_PERIOD_S = 10.0  # when stderr is not a terminal
STOP_TIMEOUT_S = 20.0  # a vehicle stops its plug-ins, then its bridge: give it time
LOG_TAIL_LINES = 15


@dataclass(frozen=True)
class VehicleSlot:
    """One vehicle of the fleet: where it lives and how it is reached."""

    index: int  # 1..N, also the MAVLink system id
    namespace: str
    state_dir: Path
    home: Home
    links: list[str]
    seed: int
    truth: Path | None

    @property
    def log_path(self) -> Path:
        return self.state_dir / "sim.log"


def fleet_namespace(base: str, index: int) -> str:
    """The bus namespace of vehicle ``index``; ValueError if it would be unusable."""
    return validate_namespace(f"{base}_v{index}")


def offset_home(home: Home, east_m: float) -> Home:
    """The same home (ground height, runway heading) moved ``east_m`` metres east."""
    lat, lon = LocalFrame(home.lat_deg, home.lon_deg).latlon(0.0, east_m)
    return dataclasses.replace(home, lat_deg=lat, lon_deg=lon)


def vehicle_truth(truth: Path | None, index: int) -> Path | None:
    """``FILE.csv`` becomes ``FILE_v<i>.csv``."""
    return None if truth is None else truth.with_name(f"{truth.stem}_v{index}{truth.suffix}")


def plan_slots(req: FleetRequest) -> list[VehicleSlot]:
    """Every vehicle's identity, ports, home and files; ValueError on an impossible fleet."""
    last_port = req.api_port_base + req.count - 1
    if req.api_port_base and last_port > 65535:
        raise ValueError(f"API ports {req.api_port_base}..{last_port} go past 65535")
    truth = Path(req.opts.truth_path) if req.opts.truth_path else None
    slots = []
    for i in range(1, req.count + 1):
        links = list(req.links)
        if req.api_port_base:
            links.append(f"udpout://127.0.0.1:{req.api_port_base + i - 1}")
        slots.append(
            VehicleSlot(
                index=i,
                namespace=fleet_namespace(req.opts.namespace, i),
                state_dir=req.state_dir / f"v{i}",
                home=offset_home(req.opts.home, (i - 1) * req.spacing_m),
                links=links,
                seed=req.opts.seed + i - 1,  # its own sensor noise and gusts
                truth=vehicle_truth(truth, i),
            )
        )
    return slots


def _number(value: float) -> str:
    return repr(float(value))  # exact round trip through the child's option parser


def shared_args(req: FleetRequest) -> list[str]:
    """The ``companion sim`` options every vehicle gets unchanged."""
    o = req.opts
    args = [
        "--aircraft", o.airframe, "--speed", "max" if o.speed is None else _number(o.speed),
        "--wind", ",".join(_number(v) for v in o.wind_ned), "--turbulence", o.turbulence,
        "--noise", _number(o.noise_scale), "--config", str(req.config),
        "--log-level", req.log_level,
    ]  # fmt: skip
    if o.airborne:
        args += ["--airborne", "--airborne-bank", _number(o.airborne_bank_deg)]
    args += ["--mount", o.mount, "--imu-hz", _number(o.rates.imu_hz)]
    if o.duration_s is not None:
        args += ["--duration", _number(o.duration_s)]
    if o.exact:
        args += ["--exact"]
    if o.start_at_s is not None:  # each vehicle arms and starts its mission then
        args += ["--start-at", _number(o.start_at_s)]
    if o.hold_at_s is not None:  # each vehicle waits there for its ground station
        args += ["--hold-at", _number(o.hold_at_s)]
    for outage in o.outages:
        args += ["--gps-outage", f"{_number(outage.start_s)}:{_number(outage.duration_s)}"]
    if req.plan is not None:
        args += ["--plan", str(req.plan)]
    return args


def vehicle_command(slot: VehicleSlot, shared: list[str]) -> list[str]:
    """The command line that runs one vehicle of the fleet."""
    h = slot.home
    home = ",".join(_number(v) for v in (h.lat_deg, h.lon_deg, h.ground_msl_m, h.heading_deg))
    cmd = [
        sys.executable, "-m", "companion", "sim", *shared, "--count", "1",
        "--sysid", str(slot.index), "--namespace", slot.namespace, "--home", home,
        "--seed", str(slot.seed), "--state-dir", str(slot.state_dir),
    ]  # fmt: skip
    for link in slot.links:
        cmd += ["--link", link]
    if slot.truth is not None:
        cmd += ["--truth", str(slot.truth)]
    return cmd


class VehicleWatch:
    """The status line of one vehicle, read from its bus as the single-vehicle monitor does."""

    def __init__(self, slot: VehicleSlot) -> None:
        self.slot = slot
        self.bus = BusNode(slot.namespace, "fleet_monitor")
        self.clock = self.bus.latest_reader("sim/clock")
        self.truth = self.bus.latest_reader("sim/truth")
        self.health = self.bus.latest_reader("system/health")
        self.status = self.bus.latest_reader("vehicle/status")
        self.last = (time.monotonic(), 0)

    def line(self) -> str:
        clock = self.clock.get()
        now, t_us = time.monotonic(), 0 if clock is None else int(clock.t_us)
        factor = (t_us - self.last[1]) / 1e6 / max(now - self.last[0], 1e-6)
        self.last = (now, t_us)
        mode = mode_name(self.status.get())
        text = status_line(t_us, factor, self.health.get(), self.truth.get(), mode)
        return f"v{self.slot.index}  {text}"

    def close(self) -> None:
        self.bus.close()


class Board:
    """One line per vehicle: redrawn in place on a terminal, logged now and then otherwise."""

    def __init__(self, watches: list[VehicleWatch]) -> None:
        self.watches = watches
        self.tty = sys.stderr.isatty()
        self.period_s = STATUS_PERIOD_S if self.tty else QUIET_STATUS_PERIOD_S
        self.next_s = time.monotonic() + self.period_s
        self.drawn = False

    def tick(self) -> None:
        if time.monotonic() < self.next_s:
            return
        self.next_s = time.monotonic() + self.period_s
        lines = [w.line() for w in self.watches]
        if not self.tty:
            for line in lines:
                log.info("%s", line)
            return
        up = f"\x1b[{len(lines)}F" if self.drawn else ""  # back to the first line drawn
        sys.stderr.write(up + "".join(line + "\x1b[K\n" for line in lines))
        sys.stderr.flush()
        self.drawn = True

    def interrupt(self) -> None:
        """A log line is about to be written: draw below it next time."""
        self.drawn = False


class Fleet:
    """The vehicles' processes: started together, watched, stopped together."""

    def __init__(self, req: FleetRequest) -> None:
        self.slots = plan_slots(req)
        self.shared = shared_args(req)
        self.procs: list[subprocess.Popen[bytes]] = []
        self.stop_requested = threading.Event()
        self.watches: list[VehicleWatch] = []

    def run(self) -> int:
        """Run every vehicle until all end, one fails, or SIGINT/SIGTERM; return the status."""
        with self._signals():
            try:
                self._start()
                self.watches = [VehicleWatch(s) for s in self.slots]
                failed = self._supervise(Board(self.watches))
            finally:
                self._stop()
                for watch in self.watches:
                    watch.close()
                for slot in self.slots:
                    cleanup_namespace(slot.namespace)  # our readers kept the vehicles' from it
        return failed if failed is not None else self._exit_status()

    @contextlib.contextmanager
    def _signals(self) -> Iterator[None]:
        def request_stop(signum: int, _frame: object) -> None:
            log.info("%s: stopping every vehicle", signal.Signals(signum).name)
            self.stop_requested.set()

        old = {s: signal.signal(s, request_stop) for s in (signal.SIGINT, signal.SIGTERM)}
        try:
            yield
        finally:
            for sig, handler in old.items():
                signal.signal(sig, handler)

    def _start(self) -> None:
        for slot in self.slots:
            slot.state_dir.mkdir(parents=True, exist_ok=True)
            api = slot.links[-1] if len(slot.links) > 1 else "none"
            log.info(
                "vehicle %d: sysid %d, bus %s, home %.6f %.6f, API %s, state and log in %s",
                slot.index, slot.index, slot.namespace, slot.home.lat_deg, slot.home.lon_deg,
                api, slot.state_dir,
            )  # fmt: skip
            with slot.log_path.open("wb") as out:
                self.procs.append(
                    subprocess.Popen(
                        vehicle_command(slot, self.shared),
                        stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT,
                        # Its own process group: a terminal's Ctrl-C reaches this process
                        # only, which forwards it once to each vehicle.
                        process_group=0, preexec_fn=die_with_parent,
                    )
                )  # fmt: skip

    def _supervise(self, board: Board) -> int | None:
        """Wait for the end; a vehicle that fails ends the fleet with its status."""
        while not self.stop_requested.is_set():
            codes = [p.poll() for p in self.procs]
            for slot, code in zip(self.slots, codes, strict=True):
                if code not in (None, 0):
                    board.interrupt()
                    log.error("vehicle %d failed (exit %d):%s", slot.index, code, _tail(slot))
                    return _status(code)
            if all(c is not None for c in codes):
                board.interrupt()
                log.info("every vehicle has finished")
                return None
            board.tick()
            self.stop_requested.wait(POLL_S)
        return None

    def _stop(self) -> None:
        """SIGTERM each vehicle still running (by pid), then SIGKILL what outlives the wait."""
        running = [p for p in self.procs if p.poll() is None]
        family = {p.pid: _descendants(p.pid) for p in running}
        for proc in running:
            proc.send_signal(signal.SIGTERM)
        deadline = time.monotonic() + STOP_TIMEOUT_S
        for proc in running:
            try:
                proc.wait(max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                log.warning("vehicle pid %d did not stop in time: killed", proc.pid)
                proc.kill()
                proc.wait()
        # A killed vehicle's bridge and plug-ins get SIGTERM from the kernel (they die with
        # their parent); wait for them so the namespace cleanup finds no live node.
        leftovers = [p for kids in family.values() for p in kids if p.is_running()]
        _, alive = psutil.wait_procs(leftovers, timeout=5.0)
        for proc in alive:
            with contextlib.suppress(psutil.NoSuchProcess):
                proc.kill()

    def _exit_status(self) -> int:
        codes = [_status(p.returncode) for p in self.procs]
        return next((c for c in codes if c != 0), 0)


def _descendants(pid: int) -> list[psutil.Process]:
    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


def _status(returncode: int) -> int:
    """A child's exit status as a shell reports it (128 + signal for a killed one)."""
    return 128 - returncode if returncode < 0 else returncode


def _tail(slot: VehicleSlot) -> str:
    try:
        lines = slot.log_path.read_text(errors="replace").splitlines()[-LOG_TAIL_LINES:]
    except OSError:
        return f" no log at {slot.log_path}"
    return f" last lines of {slot.log_path}:\n" + "\n".join(f"  {line}" for line in lines)


def run_fleet(req: FleetRequest) -> int:
    """Start ``req.count`` vehicles and return when all have stopped."""
    return Fleet(req).run()
