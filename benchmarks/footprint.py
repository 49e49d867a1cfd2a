"""What the vehicle costs a small board: memory, start-up, restart, CPU, installed size.

    uv run python benchmarks/footprint.py [--repeat 3] [--cpu-seconds 20] [--no-install]

Flies ``companion sim`` in real time on a mission (airborne, armed at simulated second
``ARM_AT_S``) and measures the vehicle's own processes: the supervisor (the ``companion sim``
process, which also runs the monitor thread), the plug-in processes and, where there is one,
the fork server; never the simulator bridge.

- PSS (proportional set size, from ``/proc/PID/smaps_rollup``) of each process disarmed
  and flying, and the total;
- start-up: from launching ``companion sim`` to the first HEARTBEAT on the UDP link (the
  simulator bridge's own start, JSBSim loading its model, is in it and is shown apart);
- restart of a plug-in killed with SIGKILL: from the kill to its new process being up (its
  first ``system/plugin_stats``, sent when its init is done), to its first step (which
  waits for its device: a 5 Hz GPS speaks up to 0.2 s later) and to its output on the bus
  again;
- CPU time per real second (the scheduler's nanosecond count of every thread,
  ``/proc/PID/task/*/schedstat``; the simulation runs at real time, and the ratio to
  simulated time is printed too) over ``--cpu-seconds`` of flight, and wake-ups per second
  (voluntary context switches): with Python in each process, a wake-up's fixed cost is
  most of what a plug-in spends (``benchmarks/wake_floor.py`` measures it);
- idle on the bench: ``companion run`` of the same config, each of its ``sim://`` devices a
  pty nobody writes to (sensors connected but silent), CPU and wake-ups per second of each
  process;
- installed size of the on-board program: ``pip install .`` (no [ground] extra) into a
  fresh venv made by uv, ``du`` of its site-packages.

The vehicle runs with its bytecode compiled, as ``pip install`` leaves it on a board: the
``.pyc`` files go to a cache outside the tree (``PYTHONPYCACHEPREFIX``), compiled first
if missing, whatever ``PYTHONDONTWRITEBYTECODE`` says here (``--source`` measures the
other way: every process compiling every module it imports, which costs ~3x the memory).

With ``--repeat N`` each flight figure is the median of N runs (the machine is shared).
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import psutil

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks.process_probes import cpu_seconds, pss_kib, vehicle_pids, wakeups  # noqa: E402
from companion.bus.namespace import cleanup_namespace  # noqa: E402
from companion.bus.node import BusNode  # noqa: E402
from companion.messages import PluginState  # noqa: E402
from mavlink_dialect import companion as m  # noqa: E402

ARM_AT_S = 12.0
DISARMED_AT_S = 8.0  # simulated second at which the disarmed vehicle is measured
FLYING_AFTER_S = 10.0  # seconds after arming before the flying figures start
KILLED = (("imu", "sensors/imu"), ("gps", "sensors/gps"), ("nav", "nav/state"))
TIMEOUT_S = 60.0
PYCACHE = Path(tempfile.gettempdir()) / "companion_footprint_pycache"
COMPILED = ("companion", "ground", "mavlink_dialect")
# The on-board program's dependencies (and the simulator's), compiled ahead like pip does.
SITE_COMPILED = (
    "numpy", "iceoryx2", "pymavlink", "shapely", "pyproj", "pynmea2", "serial",
    "psutil", "typer", "rich", "click", "jsbsim", "pygeomag", "typing_extensions",
    "shellingham", "markdown_it", "pygments", "mdurl",
)  # fmt: skip
ENV = dict(os.environ)


def use_bytecode() -> None:
    """Compile the program and its dependencies into PYCACHE; the vehicle reads them there."""
    import importlib.util

    site = [importlib.util.find_spec(n) for n in SITE_COMPILED]
    dirs = [str(REPO / n) for n in COMPILED]
    dirs += [str(Path(s.origin).parent) for s in site if s is not None and s.origin]
    ENV.pop("PYTHONDONTWRITEBYTECODE", None)
    ENV["PYTHONPYCACHEPREFIX"] = str(PYCACHE)
    cmd = [sys.executable, "-m", "compileall", "-q", "-j0", *dirs]
    subprocess.run(cmd, env=ENV, stdout=subprocess.DEVNULL, check=False)


class Vehicle:
    """A running vehicle seen from outside: its bus, its UDP link and its processes."""

    def __init__(self, cmd: list[str], namespace: str, sock: socket.socket | None) -> None:
        self.namespace, self.sock = namespace, sock
        self.t0 = time.monotonic()
        self.proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.DEVNULL, env=ENV)
        self.bus = BusNode(namespace, "footprint")
        self.health = self.bus.latest_reader("system/health")
        self.clock = self.bus.latest_reader("sim/clock")
        self.stats = self.bus.queue_reader("system/plugin_stats")
        self.parser = m.MAVLink(None)
        self.last_clock_us = 0

    def names(self) -> dict[int, str]:
        table = self.health.get()
        names = {self.proc.pid: "supervisor"}
        if table is not None:
            for row in table.rows():
                if row.pid:  # plug-ins sharing a process: the process's name
                    names[row.pid] = (row.process or row.name).decode(errors="replace")
        return names

    def labelled(self) -> dict[str, int]:
        names = self.names()
        out: dict[str, int] = {}
        for pid in vehicle_pids(self.proc.pid):
            label = names.get(pid) or _guess(pid, self.proc.pid)
            out[label if label not in out else f"{label}.{pid}"] = pid
        return out

    def sim_s(self) -> float:
        sample = self.clock.get()
        if sample is not None:
            self.last_clock_us = sample.t_us
        return self.last_clock_us / 1e6

    def wait_sim(self, seconds: float) -> None:
        deadline = time.monotonic() + TIMEOUT_S + seconds
        while self.sim_s() < seconds:
            if time.monotonic() > deadline or self.proc.poll() is not None:
                raise RuntimeError(f"simulation did not reach {seconds} s")
            time.sleep(0.05)

    def first_heartbeat(self) -> float:
        assert self.sock is not None
        deadline = time.monotonic() + TIMEOUT_S
        while time.monotonic() < deadline:
            try:
                data = self.sock.recv(65536)
            except TimeoutError:
                continue
            for msg in self.parser.parse_buffer(data) or []:
                if msg.get_type() == "HEARTBEAT":
                    return time.monotonic() - self.t0
        raise RuntimeError("no HEARTBEAT")

    def vehicle_up(self) -> float:
        """Seconds from launch until every plug-in of the table runs and has stepped."""
        deadline = time.monotonic() + TIMEOUT_S
        while time.monotonic() < deadline:
            table = self.health.get()
            if table is not None and table.count:
                rows = [r for r in table.rows() if r.group == b"core"]
                if rows and all(r.state == PluginState.RUNNING and r.step_p50_us > 0 for r in rows):
                    return time.monotonic() - self.t0
            time.sleep(0.02)
        raise RuntimeError("vehicle not up")

    def pss(self) -> dict[str, int]:
        return {name: pss_kib(pid) for name, pid in self.labelled().items()}

    def cpu(self, seconds: float) -> tuple[dict[str, float], dict[str, float], float]:
        """CPU seconds and wake-ups per real second of each process, and simulated s per
        real s."""
        pids = self.labelled()
        before = {n: (cpu_seconds(p), wakeups(p)) for n, p in pids.items()}
        wall0, sim0 = time.monotonic(), self.sim_s()
        time.sleep(seconds)
        wall, sim = time.monotonic() - wall0, self.sim_s() - sim0
        after = {n: (cpu_seconds(p), wakeups(p)) for n, p in pids.items()}
        cpu = {n: (after[n][0] - before[n][0]) / wall for n in pids}
        wakes = {n: (after[n][1] - before[n][1]) / wall for n in pids}
        return cpu, wakes, sim / wall

    def restart(self, name: str, channel: str) -> tuple[float, float, float]:
        """Kill -9 a plug-in; seconds until its new process is up (its first
        ``system/plugin_stats``, sent when its init is done), until its first step, and
        until its output is on the bus again."""
        pid = {v: k for k, v in self.names().items()}.get(name, 0)
        if not pid:
            return float("nan"), float("nan"), float("nan")
        out = self.bus.reader(channel)
        self.stats.drain()
        os.kill(pid, signal.SIGKILL)
        t_kill = time.monotonic()
        # Output of the new process is stamped after the kill; what the dead one left
        # on the bus (a Latest channel's last value) is not.
        killed_at_us = int(self.sim_s() * 1e6)
        up = stepped = flowing = float("nan")
        while time.monotonic() - t_kill < 10.0 and (stepped != stepped or flowing != flowing):
            now = time.monotonic() - t_kill
            for msg in self.stats.drain():
                if msg.name.decode() != name or msg.pid == pid:
                    continue
                up = now if up != up else up
                stepped = now if stepped != stepped and msg.steps > 0 else stepped
            if flowing != flowing and any(s.t_us > killed_at_us for s in out.drain()):
                flowing = now
            time.sleep(0.001)
        out.close()
        return up, stepped, flowing

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.bus.close()
        cleanup_namespace(self.namespace)


def _guess(pid: int, supervisor: int) -> str:
    """Not in the health table: the fork server (spawned, or forked from the supervisor)."""
    try:
        proc = psutil.Process(pid)
        cmd, parent = " ".join(proc.cmdline()), proc.ppid()
    except psutil.Error:
        return f"pid {pid}"
    return "fork server" if "zygote" in cmd or parent == supervisor else f"other {pid}"


def fly_once(cpu_s: float) -> dict[str, object]:
    tmp = Path(tempfile.mkdtemp(prefix="footprint"))
    namespace = f"fp{os.getpid()}_{int(time.time() * 1000) % 100000}"
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sock.settimeout(0.05)
    port = sock.getsockname()[1]
    cmd = [
        sys.executable, "-m", "companion", "sim", "--plan", "qgc_plans/square.plan",
        "--airborne", "--start-at", str(ARM_AT_S), "--namespace", namespace,
        "--state-dir", str(tmp / "state"), "--link", f"udpout://127.0.0.1:{port}",
        "--log-level", "ERROR",
    ]  # fmt: skip
    v = Vehicle(cmd, namespace, sock)
    try:
        res: dict[str, object] = {"heartbeat_s": v.first_heartbeat(), "up_s": v.vehicle_up()}
        v.wait_sim(DISARMED_AT_S)
        res["pss_disarmed"] = v.pss()
        v.wait_sim(ARM_AT_S + FLYING_AFTER_S)
        res["pss_flying"] = v.pss()
        res["cpu"], res["wakes"], res["sim_rate"] = v.cpu(cpu_s)
        for name, pss in v.pss().items():  # the larger of the two flying samples
            res["pss_flying"][name] = max(res["pss_flying"].get(name, 0), pss)  # type: ignore[index]
        res["restart"] = {name: v.restart(name, chan) for name, chan in KILLED}
    finally:
        v.stop()
        sock.close()
    return res


def bench_config(tmp: Path) -> tuple[Path, list[tuple[int, int]]]:
    """The sim config for ``companion run``: every ``sim://`` device a silent pty of its own
    (whatever devices the config has), its [vehicle] airframe, the host's clock, no links
    out."""
    text = (REPO / "companion" / "configs" / "sim.toml").read_text()
    ptys: list[tuple[int, int]] = []
    for name in sorted(set(re.findall(r'"sim://([^"]+)"', text))):
        ptys.append(os.openpty())
        path = os.ttyname(ptys[-1][1])
        text = text.replace(f'"sim://{name}"', f'"{path}"')
    text = text.replace('clock = "sim"', "")
    text = text.replace("[vehicle]", f'[vehicle]\nstate_dir = "{tmp / "state"}"', 1)
    text = text.replace("udpout://127.0.0.1:14550", "udpout://127.0.0.1:9")
    text = text.replace(', "udpout://127.0.0.1:14540"', "")
    config = tmp / "bench.toml"
    config.write_text(text)
    return config, ptys


def bench_idle(seconds: float) -> tuple[dict[str, float], dict[str, int], dict[str, float]]:
    """``companion run`` of the sim config with silent ptys for its devices."""
    tmp = Path(tempfile.mkdtemp(prefix="footprint_idle"))
    config, ptys = bench_config(tmp)
    namespace = f"fpidle{os.getpid()}"
    cmd = [sys.executable, "-m", "companion", "run", "-c", str(config), "--namespace", namespace,
           "--log-level", "ERROR"]  # fmt: skip
    v = Vehicle(cmd, namespace, None)
    try:
        v.vehicle_up()
        time.sleep(5.0)
        cpu, wakes, _ = v.cpu(seconds)
        pss = v.pss()
    finally:
        v.stop()
        for fd in (fd for pair in ptys for fd in pair):
            os.close(fd)
    return cpu, pss, wakes


def installed_size() -> tuple[float, float]:
    """MB of the venv's site-packages and of the whole venv after ``pip install .``."""
    with tempfile.TemporaryDirectory(prefix="footprint_venv") as tmp:
        venv = Path(tmp) / "venv"
        subprocess.run(["uv", "venv", "-q", "-p", sys.executable, str(venv)], check=True)
        subprocess.run(
            ["uv", "pip", "install", "-q", "--python", str(venv / "bin" / "python"), str(REPO)],
            check=True,
            cwd=tmp,
        )
        site = next(venv.glob("lib/python*/site-packages"))
        return _du_mb(site), _du_mb(venv)


def _du_mb(path: Path) -> float:
    out = subprocess.run(["du", "-sk", str(path)], capture_output=True, text=True, check=True)
    return int(out.stdout.split()[0]) / 1024


def _median_table(runs: list[dict[str, float]]) -> dict[str, float]:
    by: dict[str, list[float]] = defaultdict(list)
    for run in runs:
        for k, v in run.items():
            by[k].append(v)
    return {k: statistics.median(v) for k, v in by.items()}


def _order(names: list[str]) -> list[str]:
    first = ["supervisor", "fork server"]
    return [n for n in first if n in names] + sorted(n for n in names if n not in first)


def print_flight(runs: list[dict[str, object]]) -> None:
    dis = _median_table([r["pss_disarmed"] for r in runs])  # type: ignore[misc]
    fly = _median_table([r["pss_flying"] for r in runs])  # type: ignore[misc]
    cpu = _median_table([r["cpu"] for r in runs])  # type: ignore[misc]
    wakes = _median_table([r["wakes"] for r in runs])  # type: ignore[misc]
    how = "from source" if "PYTHONPYCACHEPREFIX" not in ENV else "bytecode compiled"
    print(f"companion sim, real time, square mission, {how}; medians of {len(runs)} run(s)")
    print(f"{'process':<14}{'PSS disarmed':>14}{'PSS flying':>12}{'CPU flying':>12}{'wakes/s':>9}")
    for name in _order(sorted(set(dis) | set(fly))):
        d, f, c = dis.get(name, 0) / 1024, fly.get(name, 0) / 1024, cpu.get(name, 0) * 100
        print(f"{name:<14}{d:11.1f} MB{f:9.1f} MB{c:10.2f} %{wakes.get(name, 0):9.0f}")
    total_d = statistics.median(sum(r["pss_disarmed"].values()) for r in runs) / 1024  # type: ignore[attr-defined]
    total_f = statistics.median(sum(r["pss_flying"].values()) for r in runs) / 1024  # type: ignore[attr-defined]
    total_c = statistics.median(sum(r["cpu"].values()) for r in runs) * 100  # type: ignore[attr-defined]
    rate = statistics.median(r["sim_rate"] for r in runs)  # type: ignore[misc]
    total_w = sum(wakes.values())
    print(f"{'total':<14}{total_d:11.1f} MB{total_f:9.1f} MB{total_c:10.2f} %{total_w:9.0f}")
    print(f"  (CPU: % of one core = CPU s per real s; simulated/real = {rate:.3f})")
    hb = statistics.median(r["heartbeat_s"] for r in runs)  # type: ignore[misc]
    up = statistics.median(r["up_s"] for r in runs)  # type: ignore[misc]
    print(f"start-up: launch -> first HEARTBEAT {hb:.2f} s; -> every plug-in stepping {up:.2f} s")
    for name, chan in KILLED:
        up, stepped, flowing = (
            statistics.median(r["restart"][name][k] for r in runs)  # type: ignore[index]
            for k in range(3)
        )
        print(f"restart of {name} after kill -9: up {up * 1000:4.0f} ms, first step "
              f"{stepped * 1000:4.0f} ms, {chan} again {flowing * 1000:4.0f} ms")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--cpu-seconds", type=float, default=20.0)
    ap.add_argument("--no-install", action="store_true", help="skip the installed size")
    ap.add_argument("--no-idle", action="store_true", help="skip the bench idle figure")
    ap.add_argument("--no-flight", action="store_true", help="skip the flight figures")
    ap.add_argument("--source", action="store_true", help="run without compiled bytecode")
    args = ap.parse_args()
    if not args.source:
        use_bytecode()
    if not args.no_flight:
        print_flight([fly_once(args.cpu_seconds) for _ in range(args.repeat)])
    if not args.no_idle:
        idles = [bench_idle(args.cpu_seconds) for _ in range(args.repeat)]
        cpu = _median_table([i[0] for i in idles])
        total = statistics.median(sum(i[0].values()) for i in idles) * 100
        pss = statistics.median(sum(i[1].values()) for i in idles) / 1024
        wakes = _median_table([i[2] for i in idles])
        each = ", ".join(
            f"{n} {c * 100:.2f} ({wakes.get(n, 0):.1f})"
            for n, c in sorted(cpu.items(), key=lambda i: -i[1])
        )
        print(f"idle on the bench (companion run, silent devices): CPU {total:.2f} %, "
              f"PSS {pss:.1f} MB\n  per process, % of a core (wake-ups a second): "
              f"{each}")  # fmt: skip
    if not args.no_install:
        site, venv = installed_size()
        print(f"installed (pip install . into a fresh venv): site-packages {site:.0f} MB, "
              f"venv {venv:.0f} MB")  # fmt: skip


if __name__ == "__main__":
    main()
