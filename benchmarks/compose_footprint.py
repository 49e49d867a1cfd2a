"""The vehicle's CPU and memory in both process layouts beside a bare MAVProxy relay.

    uv run python benchmarks/compose_footprint.py [--cpu-seconds 20] [--repeat 1]

A share of a core differs from one machine to the next (and on a shared machine from one
minute to the next), so each layout is measured against a yardstick measured at the same
time on the same machine: a bare MAVProxy relaying the vehicle's own telemetry,

    mavproxy.py --master=udpin:127.0.0.1:P --out=udpout:127.0.0.1:Q --daemon
                --non-interactive --default-modules=

For each layout (one process per plug-in: ``companion/configs/sim.toml``; composed:
``companion/configs/sim_composed.toml``) it flies ``companion sim`` in real time on the
square mission (airborne, armed at simulated second ``ARM_AT_S``) with its link sending to
the relay, and over the same ``--cpu-seconds`` of flight reads from ``/proc`` the CPU time
of the vehicle's processes (supervisor, which also runs the monitor, fork server and
plug-ins; never the simulator bridge) and of the relay, then the PSS of both. Then it kills
the composed vehicle's core process (kill -9) and times its return: its first counters on
``system/plugin_stats`` (its plug-ins' init done) and its IMU samples on the bus again.
The machine's load average is printed beside the figures.
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks.footprint import (  # noqa: E402
    ARM_AT_S,
    FLYING_AFTER_S,
    Vehicle,
    use_bytecode,
)
from benchmarks.process_probes import cpu_seconds, pss_kib  # noqa: E402
from companion.testing.processes import free_udp_port  # noqa: E402

CONFIGS = REPO / "companion" / "configs"
LAYOUTS = (("own processes", CONFIGS / "sim.toml"), ("composed", CONFIGS / "sim_composed.toml"))


def start_relay(master: int, out: int) -> subprocess.Popen[bytes]:
    exe = shutil.which("mavproxy.py") or str(Path(sys.executable).parent / "mavproxy.py")
    cmd = [sys.executable, exe, f"--master=udpin:127.0.0.1:{master}",
           f"--out=udpout:127.0.0.1:{out}", "--daemon", "--non-interactive",
           "--default-modules="]  # fmt: skip
    tmp = tempfile.mkdtemp(prefix="relay")  # MAVProxy writes its logs where it runs
    return subprocess.Popen(cmd, cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def tree(pid: int) -> list[int]:
    try:
        return [pid, *(c.pid for c in psutil.Process(pid).children(recursive=True))]
    except psutil.Error:
        return [pid]


def fly(config: Path, cpu_s: float, kill_core: bool) -> dict[str, float]:
    tmp = Path(tempfile.mkdtemp(prefix="compose_fp"))
    namespace = f"cfp{os.getpid()}_{int(time.time() * 1000) % 100000}"
    master, out = free_udp_port(), free_udp_port()
    relay = start_relay(master, out)
    cmd = [sys.executable, "-m", "companion", "sim", "--config", str(config),
           "--plan", "qgc_plans/square.plan", "--airborne", "--start-at", str(ARM_AT_S),
           "--namespace", namespace, "--state-dir", str(tmp / "state"),
           "--link", f"udpout://127.0.0.1:{master}", "--log-level", "ERROR"]  # fmt: skip
    v = Vehicle(cmd, namespace, None)
    res: dict[str, float] = {}
    try:
        v.vehicle_up()
        v.wait_sim(ARM_AT_S + FLYING_AFTER_S)
        pids, relay_pids = v.labelled(), tree(relay.pid)
        each = {label: cpu_seconds(p) for label, p in pids.items()}
        relay_before = sum(cpu_seconds(p) for p in relay_pids)
        wall0, sim0 = time.monotonic(), v.sim_s()
        time.sleep(cpu_s)
        wall = time.monotonic() - wall0
        for label, p in pids.items():
            res[f"cpu_pct:{label}"] = 100 * (cpu_seconds(p) - each[label]) / wall
        res["cpu_pct"] = sum(res[f"cpu_pct:{label}"] for label in pids)
        res["relay_cpu_pct"] = 100 * (sum(cpu_seconds(p) for p in relay_pids) - relay_before) / wall
        res["sim_rate"] = (v.sim_s() - sim0) / wall
        res["pss_mb"] = sum(pss_kib(p) for p in v.labelled().values()) / 1024
        res["relay_pss_mb"] = sum(pss_kib(p) for p in relay_pids) / 1024
        res["processes"] = len(pids)
        if kill_core:
            (
                res["core_started_s"],
                res["core_up_s"],
                res["core_flowing_s"],
                res["core_surfaces_s"],
            ) = restart_core(v)
    finally:
        v.stop()
        stop_relay(relay)
    return res


def stop_relay(relay: subprocess.Popen[bytes]) -> None:
    """End the relay: SIGTERM, then SIGKILL after 10 s."""
    relay.send_signal(signal.SIGTERM)
    try:
        relay.wait(10)
    except subprocess.TimeoutExpired:
        relay.kill()
        relay.wait()


def restart_core(v: Vehicle) -> tuple[float, float, float, float]:
    """Kill -9 the composed process that hosts the IMU driver; seconds until its new
    process exists, until it has published counters (a hosted plug-in's init done), until
    IMU samples flow and until the servo output answers commands again (when it hosts it)."""
    table = v.health.get()
    process = next(r.process for r in table.rows() if r.name == b"imu")
    members = {r.name.decode() for r in table.rows() if r.process == process}
    pid = next(r.pid for r in table.rows() if r.process == process)
    imu = v.bus.reader("sensors/imu")
    servos = v.bus.reader("actuators/servos")
    v.stats.drain()
    killed_at_us = int(v.sim_s() * 1e6)
    os.kill(pid, signal.SIGKILL)
    t_kill = time.monotonic()
    up = flowing = started = surfaces = float("nan")
    supervisor = psutil.Process(v.proc.pid)
    before = {c.pid for c in supervisor.children()}
    while time.monotonic() - t_kill < 30.0 and any(x != x for x in (up, flowing, surfaces)):
        now = time.monotonic() - t_kill
        if started != started and {c.pid for c in supervisor.children()} - before:
            started = now
        if up != up and any(m.pid != pid and m.name.decode() in members for m in v.stats.drain()):
            up = now
        if flowing != flowing and any(s.t_us > killed_at_us for s in imu.drain()):
            flowing = now
        if surfaces != surfaces and any(s.t_us > killed_at_us for s in servos.drain()):
            surfaces = now
        time.sleep(0.001)
    imu.close()
    servos.close()
    return started, up, flowing, surfaces


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cpu-seconds", type=float, default=20.0)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--source", action="store_true", help="run without compiled bytecode")
    args = ap.parse_args()
    if not args.source:
        use_bytecode()
    load0 = os.getloadavg()
    runs: dict[str, list[dict[str, float]]] = {name: [] for name, _ in LAYOUTS}
    for _ in range(args.repeat):
        for name, config in LAYOUTS:
            runs[name].append(fly(config, args.cpu_seconds, name == "composed"))
    load1 = os.getloadavg()
    print(f"companion sim, real time, square mission; {args.cpu_seconds:.0f} s of flight, "
          f"median of {args.repeat}; load average {load0[0]:.1f} before, {load1[0]:.1f} "
          f"after, {os.cpu_count()} cores")  # fmt: skip
    print(f"{'layout':<15}{'procs':>6}{'CPU':>9}{'relay CPU':>11}{'ratio':>7}"
          f"{'PSS':>10}{'relay PSS':>11}{'sim/real':>9}")  # fmt: skip
    for name, rs in runs.items():
        med = {k: statistics.median(r[k] for r in rs if k in r) for k in rs[0]}
        ratio = statistics.median(r["cpu_pct"] / r["relay_cpu_pct"] for r in rs)
        print(f"{name:<15}{med['processes']:6.0f}{med['cpu_pct']:8.2f}%{med['relay_cpu_pct']:10.2f}%"
              f"{ratio:6.2f}x{med['pss_mb']:7.1f} MB{med['relay_pss_mb']:8.1f} MB"
              f"{med['sim_rate']:9.3f}")  # fmt: skip
        shares = sorted(((k.split(":", 1)[1], v) for k, v in med.items() if ":" in k),
                        key=lambda kv: -kv[1])  # fmt: skip
        print("  by process: " + ", ".join(f"{k} {v:.2f}%" for k, v in shares))
        if "core_up_s" in med:
            print(f"  kill -9 of the composed process hosting the IMU: started again "
                  f"{med['core_started_s'] * 1000:.0f} ms, its first counters "
                  f"{med['core_up_s'] * 1000:.0f} ms, sensors/imu flowing again "
                  f"{med['core_flowing_s'] * 1000:.0f} ms, the servo output answering "
                  f"{med['core_surfaces_s'] * 1000:.0f} ms")  # fmt: skip


if __name__ == "__main__":
    main()
