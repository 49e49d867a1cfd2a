"""Where a restart of the supervisor in the air spends its time, phase by phase.

Usage: uv run python benchmarks/supervisor_restart.py [--restarts 4] [--every 15] [--hogs 2]

Hardware in the loop (tests/support/hil.py), real time: the vehicle flies
``qgc_plans/short_leg.plan``; once it is up, ``companion run`` is killed with SIGKILL and
started again at once (as its service would), ``--restarts`` times, ``--every`` seconds
apart. Each phase is timed from the kill on the vehicle's own time stamps: the restarted
vehicle's log lines (its clock, converted to CLOCK_MONOTONIC) and the ``t_us`` the
messages themselves carry (HIL: the vehicle's clock is CLOCK_MONOTONIC):

- ``process``: the new supervisor process is started (as its service would, at once);
- ``imports``: its vehicle libraries are imported (the first line of its log);
- ``config``: the config is read and checked;
- ``preloaded``: the plug-ins' modules are imported, the fork server forked;
- ``forkserver``: the fork server says it is ready;
- ``init <plug-in>``: the plug-in's first counters (published right after its init);
- ``imu``, ``nav``: the first IMU sample, the first navigation solution;
- ``resumed``: the commander's status says armed, in the mode it had before the kill;
- ``control``, ``servos``: the first controller output, the first servo frame written
  (the card's held trim, until the controller speaks);
- ``flying``: the first servo frame written once the controller speaks.

The project's modules are compiled first, as the tests' session does and as an installed
vehicle has them (where PYTHONDONTWRITEBYTECODE is set, each start would otherwise compile
the 1.9 MB MAVLink dialect again: 1.1 s). ``--hogs N`` runs N CPU-bound processes beside
the flight, as ``COMPANION_TEST_STRESS`` does. The load average is printed beside each
restart: the machine may be shared.
"""

from __future__ import annotations

import argparse
import asyncio
import compileall
import math
import os
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from datetime import datetime
from pathlib import Path

import psutil

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from companion.bus.node import BusNode  # noqa: E402
from tests.support.hil import HilRun  # noqa: E402
from tests.support.mavsdk_flight import plan_uploaded  # noqa: E402

PLAN = REPO / "qgc_plans" / "short_leg.plan"
CHANNELS = ("sensors/imu", "nav/state", "vehicle/status", "control/actuators",
            "actuators/servos", "system/plugin_stats")  # fmt: skip
# Lines of the supervisor's log that mark a phase (the first match after the kill).
LOG_MARKS = {
    "imports": re.compile(r" exec_control "),
    "config": re.compile(r"exec_control INFO config read"),
    "preloaded": re.compile(r"exec_control INFO fork server (forked|spawned)"),
    "forkserver": re.compile(r"exec_control INFO fork server ready"),
}
_STAMP = re.compile(r"^(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d,\d{3}) ")


class Watch(threading.Thread):
    """Every sample's own time stamp on the channels above, with what it said."""

    def __init__(self, namespace: str) -> None:
        super().__init__(daemon=True)
        self.bus = BusNode(namespace, "restart_bench")
        self.readers = {ch: self.bus.reader(ch) for ch in CHANNELS}
        self.samples: dict[str, list[tuple[float, object]]] = {ch: [] for ch in CHANNELS}
        self.last: dict[str, object] = {}
        self.stop = False

    def run(self) -> None:
        while not self.stop:
            for ch, reader in self.readers.items():
                got = [reader.get()] if hasattr(reader, "get") else list(reader.drain())
                for sample in got:
                    key = (int(sample.t_us), getattr(sample, "pid", 0)) if sample else None
                    if sample is None or (ch, key) == self.last.get(ch):
                        continue
                    self.last[ch] = (ch, key)
                    self.samples[ch].append((sample.t_us / 1e6, sample))
            self.bus.update_connections()
            time.sleep(0.002)

    def first(self, ch: str, after: float, test=lambda s: True) -> float:  # type: ignore[no-untyped-def]
        return next((t for t, s in self.samples[ch] if t > after and test(s)), math.inf)

    def inits(self, after: float, pids: set[int]) -> dict[str, float]:
        """Each restarted plug-in's first counters: its init is done."""
        done: dict[str, float] = {}
        for t, s in self.samples["system/plugin_stats"]:
            name = s.name.decode()  # type: ignore[attr-defined]
            if t > after and s.pid in pids and name not in done:  # type: ignore[attr-defined]
                done[name] = t
        return done


def _log_marks(text: str, after: float) -> dict[str, float]:
    """The monotonic time of each phase's first log line after ``after``."""
    offset = time.time() - time.monotonic()
    marks: dict[str, float] = {}
    for line in text.splitlines():
        m = _STAMP.match(line)
        if m is None:
            continue
        wall = datetime.strptime(m.group(1), "%Y-%m-%d %H:%M:%S,%f").timestamp()
        t = wall - offset
        for name, pattern in LOG_MARKS.items():
            if name not in marks and t > after - 0.01 and pattern.search(line):
                marks[name] = t
    return marks


async def _fly(run: HilRun, watch: Watch, opts: argparse.Namespace) -> list[dict]:
    results = []
    async with plan_uploaded(run.port, str(PLAN)) as flight:
        await flight.action.arm()
        await flight.mission.start_mission()
        await asyncio.sleep(opts.first)  # the climb-out
        for k in range(opts.restarts):
            before = watch.samples["vehicle/status"][-1][1]
            load = os.getloadavg()
            run.vehicle.send_signal(signal.SIGKILL)
            run.vehicle.wait()
            killed = time.monotonic()
            name = f"vehicle_restart{k}"
            started = time.monotonic()
            run.restart_vehicle(name)
            await asyncio.sleep(opts.every)
            results.append(_phases(run, watch, name, killed, started, before, load))
            if opts.show_log and k == opts.restarts - 1:
                print(run.log(name)[:6000])
    return results


def _phases(run, watch, name, killed, started, before, load) -> dict:  # type: ignore[no-untyped-def]
    pids = {p.pid for p in psutil.Process(run.vehicle.pid).children(recursive=True)}
    marks = _log_marks(run.log(name), killed)
    # Nothing the new vehicle makes comes before its fork server: samples earlier than that
    # are the old plug-ins' last (they die with the supervisor, but not at once).
    after = marks.get("forkserver", killed)
    resumed = watch.first("vehicle/status", after, lambda s: s.armed and s.mode == before.mode)
    row = {"load": load, "process": started, **marks}
    row["inits"] = watch.inits(after, pids)
    row["imu"] = watch.first("sensors/imu", after)
    row["nav"] = watch.first("nav/state", after)
    row["resumed"] = resumed
    row["control"] = watch.first("control/actuators", after)
    row["servos"] = watch.first("actuators/servos", after)
    row["flying"] = watch.first("actuators/servos", row["control"] - 1e-6)
    row["killed"] = killed
    return row


def _table(rows: list[dict]) -> None:
    names = ["process", "imports", "config", "preloaded", "forkserver"]
    plugins = sorted({p for r in rows for p in r["inits"]},
                     key=lambda p: statistics.median(r["inits"].get(p, math.inf) - r["killed"]
                                                     for r in rows))  # fmt: skip
    names += [f"init {p}" for p in plugins]
    names += ["imu", "nav", "resumed", "control", "servos", "flying"]
    loads = " | ".join(f"{r['load'][0]:.1f}" for r in rows)
    print(f"phase (s after the kill; load 1 min per restart: {loads})")
    print("| phase | " + " | ".join(f"#{i + 1}" for i in range(len(rows))) + " | median |")
    print("|---" * (len(rows) + 2) + "|")
    for n in names:
        vals = []
        for r in rows:
            t = r["inits"].get(n[5:], math.inf) if n.startswith("init ") else r.get(n, math.inf)
            vals.append(t - r["killed"])
        med = statistics.median(vals)
        print(f"| {n} | " + " | ".join(f"{v:.2f}" for v in vals) + f" | {med:.2f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--restarts", type=int, default=4)
    ap.add_argument("--every", type=float, default=15.0, help="seconds between kills")
    ap.add_argument("--first", type=float, default=45.0, help="seconds of mission first")
    ap.add_argument("--show-log", action="store_true", help="print the last restart's log")
    ap.add_argument("--hogs", type=int, default=0, help="CPU-bound processes beside it")
    opts = ap.parse_args()
    for package in ("companion", "bridges", "ground", "mavlink_dialect"):
        compileall.compile_dir(REPO / package, quiet=1)
    hogs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(opts.hogs)]
    try:
        rows = _measure(opts)
    finally:
        for hog in hogs:
            hog.kill()
            hog.wait()
    print(f"plan {PLAN.name}; {len(rows)} restarts; {opts.hogs} CPU hogs; load {os.getloadavg()}")
    _table(rows)


def _measure(opts: argparse.Namespace) -> list[dict]:
    with tempfile.TemporaryDirectory() as tmp:
        run = HilRun(Path(tmp), "--duration", str(int(opts.first + 60 + 20 * opts.restarts)))
        watch = Watch(run.namespace)
        watch.start()
        try:
            rows = asyncio.run(_fly(run, watch, opts))
        finally:
            watch.stop = True
            watch.join()
            watch.bus.close()
            run.stop()
    return rows


if __name__ == "__main__":
    main()
