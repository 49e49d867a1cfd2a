"""The vehicle on an emulated arm64 board against the same vehicle native, both in HIL.

    python3 -m uv run python benchmarks/emulated_board.py [--plan short_leg.plan]
        [--only native|emulated] [--probe-seconds 120]

Needs root and the emulated board set up (board/build_wheelhouse.py, then
``board/emulated_board.sh setup``). Each flight is hardware in the loop in real time:
``companion hil --ptys DIR`` on this machine makes the device lines, and the vehicle,
started apart with the shipped HIL config, reads them:
- ``native``: ``companion run`` on this machine's CPython (x86_64);
- ``emulated``: ``companion run`` in the Debian bookworm arm64 root under qemu-user,
  installed from the wheelhouse (``board/emulated_board.sh run``), the ptys' links under
  the root's /run/hil-lines, its MAVLink on UDP to this machine.
MAVSDK uploads the plan, arms and starts the mission (tests/support/mavsdk_flight.py). For
each it prints: whether the mission finished, ATTITUDE messages a second on the link, IMU
sample → Mini SSC frame written p50/p99 (benchmarks/servo_latency_probe.py, run beside the
vehicle on its own bus), CPU per process (% of one core, from the scheduler's count, over
the flight after the first minute) and PSS (the largest seen; under emulation it includes
qemu's own memory), and the tracking score from the simulator's truth
(ground/campaign/scoring.py).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import re
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks.process_probes import cpu_seconds, pss_kib  # noqa: E402
from companion.bus.namespace import cleanup_namespace  # noqa: E402
from companion.navigation.estimate_csv import read_estimate  # noqa: E402
from ground.campaign.scoring import score_track  # noqa: E402
from ground.campaign.spec import PLANS  # noqa: E402
from mavlink_dialect import companion as m  # noqa: E402
from tests.protocol.mav_client import free_udp_port  # noqa: E402
from tests.support.mavsdk_flight import fly_plan  # noqa: E402
from tests.support.vehicle import companion_env, unique_namespace  # noqa: E402

BOARD = REPO / "board" / "emulated_board.sh"
ROOT = Path("/work/arm64/root")
SHIPPED = REPO / "companion" / "configs" / "hil.toml"
PROBE = REPO / "benchmarks" / "servo_latency_probe.py"
SETTLE_S = 60.0  # CPU is counted from here on: start-up and arming left out
SAMPLE_S = 5.0


def vehicle_config(path: Path, lines: str, ports: tuple[int, int], namespace: str,
                   state_dir: str) -> Path:  # fmt: skip
    """The shipped HIL config on these lines, with two links: MAVSDK's and the counter's."""
    text = SHIPPED.read_text().replace("/tmp/companion-hil", lines)
    links = ", ".join(f'"udpout://127.0.0.1:{p}"' for p in ports)
    text = text.replace('"udpout://127.0.0.1:14550", "udpout://127.0.0.1:14540"', links)
    head = f'[vehicle]\nnamespace = "{namespace}"\nstate_dir = "{state_dir}"\n'
    path.write_text(text.replace("[vehicle]\n", head))
    return path


class Watch(threading.Thread):
    """ATTITUDE arrivals on one UDP port, and every few seconds the CPU time and PSS of
    the vehicle's processes (the supervisor and its children)."""

    def __init__(self, sock: socket.socket, supervisor: int) -> None:
        super().__init__(daemon=True)
        self.sock, self.supervisor, self.done = sock, supervisor, threading.Event()
        self.attitude: list[float] = []
        self.samples: list[tuple[float, dict[int, float], dict[int, int]]] = []
        self.fork_servers: set[int] = set()

    def run(self) -> None:
        import psutil

        parser, next_sample = m.MAVLink(None), 0.0
        self.sock.settimeout(0.2)
        while not self.done.is_set():
            try:
                for msg in parser.parse_buffer(self.sock.recv(65536)) or []:
                    if msg.get_type() == "ATTITUDE":
                        self.attitude.append(time.monotonic())
            except (TimeoutError, m.MAVError):
                pass
            if time.monotonic() >= next_sample:
                next_sample = time.monotonic() + SAMPLE_S
                try:
                    kids = psutil.Process(self.supervisor).children(recursive=True)
                except psutil.Error:
                    continue
                pids = [self.supervisor, *(k.pid for k in kids)]
                self.fork_servers |= {k.pid for k in kids if _is_fork_server(k)}
                cpu = {p: cpu_seconds(p) for p in pids}
                self.samples.append((time.monotonic(), cpu, {p: pss_kib(p) for p in pids}))


def _is_fork_server(proc: object) -> bool:
    try:
        return "zygote" in " ".join(proc.cmdline())  # type: ignore[attr-defined]
    except Exception:  # gone, or not ours to read: not the fork server then
        return False


def names(log: str) -> dict[int, str]:
    """pid → plug-in name, from the supervisor's 'started NAME (kind) pid N' lines."""
    return {int(p): n for n, p in re.findall(r"started (\S+) \(\S+\) pid (\d+)", log)}


def per_process(watch: Watch, log: str) -> dict[str, tuple[float, int]]:
    """name → (% of one core after SETTLE_S, the largest PSS in KiB)."""
    if len(watch.samples) < 2:
        return {}
    start = watch.samples[0][0] + SETTLE_S
    first = next((s for s in watch.samples if s[0] >= start), watch.samples[0])
    last, label = watch.samples[-1], {watch.supervisor: "supervisor", **names(log)}
    label |= {pid: "fork server" for pid in watch.fork_servers}
    out = {}
    for pid, cpu_end in last[1].items():
        cpu_start = first[1].get(pid)
        pct = 100 * (cpu_end - cpu_start) / (last[0] - first[0]) if cpu_start else float("nan")
        pss = max(s[2].get(pid, 0) for s in watch.samples)
        # The fork server is the one child not started as a plug-in (forked, it has the
        # supervisor's command line).
        out[label.get(pid, "fork server")] = (pct, pss)
    return out


class Board:
    """Where the vehicle runs: this machine, or the emulated board's root."""

    def __init__(self, pace: str, tmp: Path, namespace: str) -> None:
        self.emulated, self.tmp, self.namespace = pace == "emulated", tmp, namespace
        self.lines_host = ROOT / "run" / "hil-lines" if self.emulated else tmp / "lines"
        self.lines = "/run/hil-lines" if self.emulated else str(self.lines_host)
        self.state_dir = "/var/lib/companion-hil" if self.emulated else str(tmp / "state")
        self.proc: subprocess.Popen[str] | None = None

    def start(self, config: Path) -> int:
        """Start ``companion run``; the supervisor's pid."""
        if self.emulated:
            subprocess.run([str(BOARD), "run", str(config)], check=True)
            return int(Path(f"{ROOT}.state/pid").read_text())
        with (self.tmp / "vehicle.log").open("w") as out:
            cmd = [sys.executable, "-m", "companion", "run", "--config", str(config)]
            self.proc = subprocess.Popen(cmd, cwd=REPO, env=companion_env(self.namespace),
                                         stdout=out, stderr=out, text=True)  # fmt: skip
        return self.proc.pid

    def probe(self) -> subprocess.Popen[str]:
        """The latency probe on the vehicle's bus, until SIGINT."""
        if self.emulated:
            (ROOT / "opt" / "board").mkdir(parents=True, exist_ok=True)
            (ROOT / "opt" / "board" / PROBE.name).write_text(PROBE.read_text())
            cmd = [str(BOARD), "exec", "python", f"/opt/board/{PROBE.name}"]
        else:
            cmd = [sys.executable, str(PROBE)]
        env = companion_env(self.namespace)
        cmd += [self.namespace, "100000"]
        return subprocess.Popen(cmd, cwd=REPO, text=True, env=env, stdout=subprocess.PIPE)

    def stop(self) -> None:
        if self.emulated:
            subprocess.run([str(BOARD), "stop"], check=True)
        elif self.proc is not None:
            self.proc.terminate()
            self.proc.wait(timeout=30)

    def log(self) -> str:
        path = ROOT / "var/log/companion.log" if self.emulated else self.tmp / "vehicle.log"
        return path.read_text(errors="replace")


def _end(proc: subprocess.Popen[str]) -> str:
    """SIGINT a process, and what it printed."""
    proc.send_signal(2)
    try:
        return proc.communicate(timeout=60)[0] or ""
    except subprocess.TimeoutExpired:
        proc.kill()
        return proc.communicate()[0] or ""


def fly(pace: str, plan: Path) -> dict:
    """One HIL flight of the plan with the vehicle on ``pace``'s board; its figures."""
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp, namespace = Path(tmp_name), unique_namespace("board")
        board, port = Board(pace, tmp, namespace), free_udp_port()
        att = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        att.bind(("127.0.0.1", 0))
        ports = (port, att.getsockname()[1])
        config = vehicle_config(tmp / "vehicle.toml", board.lines, ports, namespace,
                                board.state_dir)  # fmt: skip
        truth = tmp / "truth.csv"
        with (tmp / "hil.log").open("w") as out:
            sim = subprocess.Popen(
                [sys.executable, "-m", "companion", "hil", "--ptys", str(board.lines_host),
                 "--truth", str(truth), "--duration", "1500"],
                cwd=REPO, env=companion_env(namespace), stdout=out, stderr=out, text=True,
            )  # fmt: skip
        started = time.monotonic()
        watch, probe = Watch(att, board.start(config)), board.probe()
        watch.start()
        try:
            seen = asyncio.run(fly_plan(port, str(plan), 1100.0))
        finally:
            watch.done.set()
            probe_out = _end(probe)
            processes = per_process(watch, board.log())
            board.stop()
            _end(sim)
            cleanup_namespace(namespace)
        rate = len([t for t in watch.attitude if t > started + SETTLE_S])
        span = (watch.attitude[-1] - started - SETTLE_S) if watch.attitude else 0.0
        score = score_track(read_estimate(truth), plan, "c172p", (0.0, 0.0, 0.0))
        latency = json.loads(probe_out.strip().splitlines()[-1]) if probe_out.strip() else {}
        return {"finished": seen.get("finished"), "attitude_hz": rate / span if span > 0 else 0,
                "latency": latency, "processes": processes, **score.as_row()}  # fmt: skip


def report(results: dict[str, dict]) -> None:
    paces = list(results)
    print(f"{'':34}" + "".join(f"{p:>18}" for p in paces))

    def row(label: str, fmt: str, get) -> None:  # type: ignore[no-untyped-def]
        print(f"{label:34}" + "".join(f"{fmt.format(get(results[p])):>18}" for p in paces))

    row("mission finished", "{}", lambda r: r["finished"])
    row("ATTITUDE /s", "{:.1f}", lambda r: r["attitude_hz"])
    for q in ("p50", "p99", "max"):
        label = f"IMU -> servo frame {q} ms"
        row(label, "{:.1f}", lambda r, q=q: r["latency"].get(f"{q}_ms", 0))
    row("cross-track RMS / p95 m", "{}",
        lambda r: f"{r['xtrack_rms_m']:.2f} / {r['xtrack_p95_m']:.2f}")  # fmt: skip
    row("height RMS m", "{:.2f}", lambda r: r["alt_rms_m"])
    row("airspeed RMS m/s", "{:.2f}", lambda r: r["airspeed_rms_m_s"])
    names = sorted({n for r in results.values() for n in r["processes"]})
    print("CPU % of one core / PSS MB per process")
    for n in names:
        row(f"  {n}", "{}", lambda r, n=n: "{:.1f} / {:.0f}".format(
            r["processes"].get(n, (float("nan"), 0))[0],
            r["processes"].get(n, (0, 0))[1] / 1024))  # fmt: skip
    row("  total", "{}", lambda r: "{:.1f} / {:.0f}".format(
        sum(v[0] for v in r["processes"].values() if v[0] == v[0]),
        sum(v[1] for v in r["processes"].values()) / 1024))  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plan", default="short_leg.plan")
    ap.add_argument("--only", choices=("native", "emulated"))
    args = ap.parse_args()
    plan = (PLANS / args.plan) if not Path(args.plan).exists() else Path(args.plan).resolve()
    paces = [args.only] if args.only else ["native", "emulated"]
    results = {}
    for pace in paces:
        results[pace] = fly(pace, plan)
        print(f"{pace}: {json.dumps(results[pace])}", flush=True)
    print(f"c172p {plan.name}, calm, hardware in the loop in real time")
    report(results)


if __name__ == "__main__":
    main()
