"""The composed vehicle's CPU, thread by thread, beside a bare MAVProxy relay, in real time.

    uv run python benchmarks/thread_budget.py [--seconds 20] [--config FILE] [--no-relay]

Flies ``companion sim`` in real time on the square mission (armed at simulated second
``ARM_AT_S``), by default with its link sending to a bare MAVProxy relay as
``compose_footprint.py`` does (a ground station the link hears, as in that benchmark), and
over ``--seconds`` of flight reads from ``/proc/PID/task/TID`` every thread of the
vehicle's processes (and of the relay): its user and system time (``stat``, 10 ms ticks),
its CPU time (``schedstat``, nanoseconds) and its voluntary and involuntary context
switches (``status``: a voluntary one is a sleep, for input or for the interpreter's lock).
A composed process names each thread after its plug-in. Beside it, each plug-in's steps a
second from its counters on ``system/plugin_stats``: unlike a share of a core, the steps
and the wake-ups do not depend on how busy the machine is, so they show a wake-up that
does nothing (a step with no input to act on) wherever it is measured.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks.compose_footprint import start_relay, stop_relay  # noqa: E402
from benchmarks.footprint import ARM_AT_S, FLYING_AFTER_S, Vehicle, use_bytecode  # noqa: E402
from companion.testing.processes import free_udp_port  # noqa: E402

TICK_S = 1.0 / os.sysconf("SC_CLK_TCK")
COMPOSED = REPO / "companion" / "configs" / "sim_composed.toml"
# Per thread: name, user s, system s, CPU s (schedstat), voluntary, involuntary switches.
Row = tuple[str, float, float, float, int, int]


def _thread(task: Path) -> Row | None:
    try:
        name = (task / "comm").read_text().strip()
        stat = (task / "stat").read_text()
        fields = stat[stat.rindex(")") + 2 :].split()  # from field 3 on
        cpu_ns = int((task / "schedstat").read_text().split()[0])
        switches = {}
        for line in (task / "status").read_text().splitlines():
            key, _, value = line.partition(":")
            if key.endswith("ctxt_switches"):
                switches[key] = int(value)
    except (OSError, ValueError, IndexError):
        return None  # the thread ended
    return (name, int(fields[11]) * TICK_S, int(fields[12]) * TICK_S, cpu_ns / 1e9,
            switches.get("voluntary_ctxt_switches", 0),
            switches.get("nonvoluntary_ctxt_switches", 0))  # fmt: skip


def threads(pids: dict[str, int]) -> dict[tuple[str, int], Row]:
    """Every thread of the labelled processes, by (process label, thread id)."""
    out = {}
    for label, pid in pids.items():
        try:
            tids = os.listdir(f"/proc/{pid}/task")
        except OSError:
            continue
        for tid in tids:
            row = _thread(Path(f"/proc/{pid}/task/{tid}"))
            if row is not None:
                out[(label, int(tid))] = row
    return out


def plugin_steps(
    v: Vehicle, cpu: dict[str, list[float]] | None = None
) -> dict[str, tuple[int, int]]:
    """Each plug-in's last counters on the bus: (steps, t_us); each one's CPU shares
    (``cpu_pct``, its own steps: a chained plug-in's are its own, not its producer's) are
    appended to ``cpu``."""
    out = {}
    for s in v.stats.drain():
        name = s.name.decode()
        out[name] = (s.steps, s.t_us)
        if cpu is not None:
            cpu.setdefault(name, []).append(s.cpu_pct)
    return out


def sleep_reading_cpu(v: Vehicle, seconds: float, cpu: dict[str, list[float]]) -> None:
    """Sleep ``seconds``, reading the plug-ins' counters (once a second each) as they come."""
    end = time.monotonic() + seconds
    while (left := end - time.monotonic()) > 0:
        time.sleep(min(0.5, left))
        plugin_steps(v, cpu)


def fly(seconds: float, config: Path, relay_on: bool) -> dict[str, Any]:
    tmp = Path(tempfile.mkdtemp(prefix="thread_budget"))
    namespace = f"tb{os.getpid()}_{int(time.time() * 1000) % 100000}"
    master = free_udp_port()
    relay = start_relay(master, free_udp_port()) if relay_on else None
    link = f"udpout://127.0.0.1:{master}" if relay_on else "udpout://127.0.0.1:9"
    cmd = [sys.executable, "-m", "companion", "sim", "--config", str(config),
           "--plan", "qgc_plans/square.plan", "--airborne", "--start-at", str(ARM_AT_S),
           "--namespace", namespace, "--state-dir", str(tmp / "state"),
           "--link", link, "--log-level", "ERROR"]  # fmt: skip
    v = Vehicle(cmd, namespace, None)
    try:
        v.vehicle_up()
        v.wait_sim(ARM_AT_S + FLYING_AFTER_S)
        pids = v.labelled()
        if relay is not None:
            pids["relay"] = relay.pid
        plugin_steps(v)
        time.sleep(1.2)  # counters come once a second: a fresh set to start from
        steps0 = plugin_steps(v)
        before, wall0, sim0 = threads(pids), time.monotonic(), v.sim_s()
        shares: dict[str, list[float]] = {}
        sleep_reading_cpu(v, seconds, shares)
        after, wall, sim = threads(pids), time.monotonic() - wall0, v.sim_s() - sim0
        time.sleep(1.2)
        steps1 = plugin_steps(v)
    finally:
        v.stop()
        if relay is not None:
            stop_relay(relay)
    rows = []
    for key, (name, user, system, cpu, vol, invol) in after.items():
        if key in before:
            _, user0, system0, cpu0, vol0, invol0 = before[key]
            pct = [100 * (user - user0) / wall, 100 * (system - system0) / wall,
                   100 * (cpu - cpu0) / wall]  # fmt: skip
            rows.append((key[0], name, *pct, (vol - vol0) / wall, (invol - invol0) / wall))
    steps = {}
    for name, (n1, t1) in steps1.items():
        if name in steps0 and t1 > steps0[name][1]:
            steps[name] = (n1 - steps0[name][0]) / ((t1 - steps0[name][1]) / 1e6)
    plugin_cpu = {name: sum(c) / len(c) for name, c in shares.items() if c}
    return {"rows": rows, "steps": steps, "cpu": plugin_cpu, "wall": wall, "sim_rate": sim / wall}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--config", type=Path, default=COMPOSED)
    ap.add_argument("--no-relay", action="store_true", help="link to a port nobody hears")
    args = ap.parse_args()
    use_bytecode()
    load0 = os.getloadavg()[0]
    res = fly(args.seconds, args.config, not args.no_relay)
    print(f"{args.config.name}, real time, square mission, {res['wall']:.0f} s of flight "
          f"(sim/real {res['sim_rate']:.3f}); load average {load0:.1f} before, "
          f"{os.getloadavg()[0]:.1f} after, {os.cpu_count()} cores")  # fmt: skip
    print(f"{'process':<12}{'thread':<16}{'user %':>8}{'sys %':>7}{'CPU %':>7}"
          f"{'vol/s':>8}{'invol/s':>8}")  # fmt: skip
    totals: dict[str, list[float]] = {}
    for row in sorted(res["rows"], key=lambda r: (r[0] == "relay", -r[4])):
        total = totals.setdefault("relay" if row[0] == "relay" else "vehicle", [0.0] * 5)
        for i in range(5):
            total[i] += row[2 + i]
        if row[4] >= 0.005 or row[5] >= 0.5:
            print(f"{row[0]:<12}{row[1]:<16}{row[2]:8.2f}{row[3]:7.2f}{row[4]:7.2f}"
                  f"{row[5]:8.1f}{row[6]:8.1f}")  # fmt: skip
    for what, t in totals.items():
        print(f"{what + ', all threads':<28}{t[0]:8.2f}{t[1]:7.2f}{t[2]:7.2f}"
              f"{t[3]:8.1f}{t[4]:8.1f}")  # fmt: skip
    print("plug-in steps a second: "
          + ", ".join(f"{n} {s:.1f}" for n, s in sorted(res["steps"].items())))  # fmt: skip
    by_share = sorted(res["cpu"].items(), key=lambda x: -x[1])
    if not any(c for _, c in by_share):
        return  # a plug-in of its own process says its share in the table above
    print("plug-in CPU % (its own steps, also those run on its producer's thread): "
          + ", ".join(f"{n} {c:.2f}" for n, c in by_share))  # fmt: skip


if __name__ == "__main__":
    main()
