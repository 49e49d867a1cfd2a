"""Instructions per simulated second of the composed vehicle process, counted by callgrind.

    uv run python benchmarks/flight_instructions.py [--speed 0.1] [--from-s 20] [--window-s 5]

Flies ``companion sim`` in exact lockstep (``--speed max --exact``, armed in the air at
simulated second 10 on ``qgc_plans/square.plan``) with the composed process ("vehicle" of
``sim_composed.toml``) started under ``valgrind --tool=callgrind --instr-atstart=no`` through
``COMPANION_WRAP`` (``companion/exec_control/profiling.py``). Counting is switched on at
simulated second ``--from-s`` and off ``--window-s`` later (``callgrind_control -i``), so
start-up and imports are not in it. Prints the instructions per simulated second of the
process and of each of its threads (a plug-in's thread; the chained flight path, IMU →
navigator → controller → servos, runs on the IMU driver's), and the callgrind files; read
one with ``callgrind_annotate FILE`` (C level: under Python 3.11 the interpreter's own
functions, numpy's, iceoryx2's, not Python function names).

Instructions do not depend on the machine's load as CPU seconds do, with one exception the
window's wall seconds (printed) show: under callgrind the vehicle runs some 5-20 times
slower than real time, so what runs per wall second (counters and step-time percentiles
once a second, timeouts of threads whose input the chain takes, bus connection upkeep)
weighs that much more than in flight. Compare runs of similar wall seconds, or the IMU
thread plus the navigator's, controller's and servos' own threads, whose samples move
between them as the timeouts fall. Exact lockstep also makes the logger wake for every
IMU sample (``in_step``), which it does not do in real time. Kernel time (system calls, thread
switches) is not counted at all.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks import footprint  # noqa: E402
from benchmarks.footprint import Vehicle, use_bytecode  # noqa: E402

ARM_AT_S = 10.0
TIMEOUT_S = 1800.0  # wall seconds: under callgrind the vehicle runs ~50x slower


def vehicle_pid(v: Vehicle, process: str) -> int:
    deadline = time.monotonic() + TIMEOUT_S
    while time.monotonic() < deadline:
        table = v.health.get()
        for row in table.rows() if table is not None else []:
            if row.pid and (row.process or row.name).decode() == process:
                return row.pid
        time.sleep(0.2)
    raise RuntimeError(f"no process {process!r}")


def wait_sim(v: Vehicle, seconds: float) -> None:
    deadline = time.monotonic() + TIMEOUT_S
    while v.sim_s() < seconds:
        if time.monotonic() > deadline or v.proc.poll() is not None:
            raise RuntimeError(f"simulation did not reach {seconds} s")
        time.sleep(0.1)


def toggle(pid: int, on: bool, v: Vehicle) -> float:
    """Switch counting on or off; the simulated second it happened at (midpoint)."""
    before = v.sim_s()
    subprocess.run(["callgrind_control", "-i", "on" if on else "off", str(pid)], check=True,
                   stdout=subprocess.DEVNULL)  # fmt: skip
    return (before + v.sim_s()) / 2


def fly(args: argparse.Namespace, out: Path) -> tuple[float, int, list[str]]:
    """Fly, count the window; (simulated seconds counted, the process id, its threads)."""
    tmp = Path(tempfile.mkdtemp(prefix="flight_instr"))
    namespace = f"fi{os.getpid()}_{int(time.time() * 1000) % 100000}"
    footprint.ENV["COMPANION_WRAP"] = (
        f"valgrind -q --log-file={out}/vg.%p.log --tool=callgrind --instr-atstart=no"
        f" --separate-threads=yes --callgrind-out-file={out}/cg.%p"
    )
    footprint.ENV["COMPANION_WRAP_ONLY"] = args.process
    cmd = [sys.executable, "-m", "companion", "sim", "--config", str(args.config),
           "--plan", args.plan, "--airborne", "--start-at", str(ARM_AT_S), "--speed", args.speed,
           "--exact", "--namespace", namespace, "--state-dir", str(tmp / "state"),
           "--link", "udpout://127.0.0.1:9", "--log-level", "ERROR"]  # fmt: skip
    v = Vehicle(cmd, namespace, None)
    try:
        pid = vehicle_pid(v, args.process)
        wait_sim(v, args.from_s)
        start, wall = toggle(pid, True, v), time.monotonic()
        wait_sim(v, args.from_s + args.window_s)
        end, wall = toggle(pid, False, v), time.monotonic() - wall
        names = thread_names(pid)
        subprocess.run(["callgrind_control", "-d", str(pid)], check=True, stdout=subprocess.DEVNULL)
    finally:
        v.stop()
    print(f"window: {end - start:.2f} simulated s in {wall:.0f} wall s")
    return end - start, pid, names


def thread_names(pid: int) -> list[str]:
    """The process's threads' names in the order they started (callgrind's thread numbers,
    unless one ended and another took its place)."""
    tasks = sorted(Path(f"/proc/{pid}/task").iterdir(), key=lambda p: int(p.name))
    return [(t / "comm").read_text().strip() for t in tasks]


def thread_instructions(out: Path, pid: int) -> dict[str, int]:
    """Instructions of each thread of the dump (``--separate-threads``), by file name."""
    totals: dict[str, int] = {}
    for path in sorted(out.glob(f"cg.{pid}*")):
        text = path.read_text(errors="replace")
        count = max((int(n) for n in re.findall(r"^(?:summary|totals): (\d+)", text, re.M)),
                    default=0)  # fmt: skip
        if count:
            totals[path.name] = count
    return totals


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", type=Path, default=REPO / "companion/configs/sim_composed.toml")
    ap.add_argument("--plan", default="qgc_plans/square.plan")
    ap.add_argument("--process", default="vehicle", help="the process to count")
    ap.add_argument("--from-s", type=float, default=20.0, help="simulated second to start")
    ap.add_argument("--window-s", type=float, default=5.0, help="simulated seconds counted")
    pace = "companion sim --speed: a pace (0.1) below callgrind's keeps the wall seconds alike"
    ap.add_argument("--speed", default="max", help=pace)
    ap.add_argument("--out", type=Path, default=None, help="folder for the callgrind files")
    args = ap.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="flight_instr_out"))
    out.mkdir(parents=True, exist_ok=True)
    use_bytecode()
    seconds, pid, names = fly(args, out)
    threads = thread_instructions(out, pid)
    total = sum(threads.values())
    print(f"{args.process}: {total / seconds / 1e6:.1f} M instructions per simulated second "
          f"({total:,} in {seconds:.2f} simulated s from {args.from_s:g} s); {out}")  # fmt: skip
    for file, count in sorted(threads.items(), key=lambda kv: -kv[1]):
        number = int(file.rsplit("-", 1)[1])  # callgrind's thread number, from 1
        name = names[number - 1] if number <= len(names) else "?"
        print(f"  {name:12s} {count / seconds / 1e6:7.1f} M/s  ({file})")


if __name__ == "__main__":
    main()
