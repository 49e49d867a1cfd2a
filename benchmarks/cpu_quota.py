"""A small busy board: the vehicle flying a plan in real time inside a CPU quota.

Usage: uv run python benchmarks/cpu_quota.py [--plan square.plan]
       [--quotas exact,none,25,15,10,7.5,5] [--quick] [--composed]

Each row flies the plan through hardware in the loop on this machine (tests/support/hil.py:
``companion hil --ptys`` and ``companion run`` with the shipped HIL config, started apart,
joined only by ptys and UDP), the mission uploaded, armed and started by MAVSDK. The
vehicle (``companion run`` and every process it starts) is confined by a cgroup v1 CPU
quota, a share of one core (tests/support/cpu_quota.py; needs root); the simulator, the
ground station and the watcher stay outside it. ``none`` flies unconfined; ``exact`` flies
the same plan in exact lockstep (``companion sim --exact``) as the reference. ``--quick``
flies short_leg.plan at 15 % only; ``--composed`` puts every plug-in in one process
(``process = "vehicle"``, as ``companion/configs/aircraft.toml`` offers a small board).

Per row: completed or not; cross-track RMS / p95, height RMS from the simulator's truth
(the campaign's score); for a plan that ends in a landing, on a line of its own, the
touchdown along and across the landing point and its sink (``benchmarks/landing.py``'s
score: ``--plan benchmarks/plans/circuit_east.plan``; MAVSDK's plan import refuses
QGroundControl's landing pattern); IMU first byte -> Mini SSC frame written, p50 / p99 (as
benchmarks/latency.py: the IMU driver's stamp against a bus subscriber's clock); the
navigator's state rate and the telemetry rates a ground station gets (ATTITUDE,
GLOBAL_POSITION_INT, on a UDP endpoint of its own), from arming to the mission's end; the
vehicle's own dropped and bad-frame counters (its health table, as ``companion status``)
and the bytes the simulator's IMU line could not hand over; the CPU the quota's cgroup
used and the share of its periods throttled; the load average of the machine (other jobs
share its cores) and the first thing that went wrong (a warning the vehicle sent, a
plug-in restarted, an arm refusal, a timeout).
"""

from __future__ import annotations

import argparse
import asyncio
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks.quota_watch import Watch, fly_watched  # noqa: E402
from companion.control.mission.plan import checked_plan  # noqa: E402
from companion.navigation.estimate_csv import read_estimate  # noqa: E402
from ground.campaign.flight_run import FlightJob, fly_flight, plan_lands  # noqa: E402
from ground.campaign.landing_score import (  # noqa: E402
    LandingScore,
    landing_score_for_plan,
    read_truth,
)
from ground.campaign.scoring import score_track  # noqa: E402
from ground.campaign.spec import PLANS, SIM_CONFIG, Flight  # noqa: E402
from tests.support.cpu_quota import CpuQuota, unusable_reason  # noqa: E402
from tests.support.hil import HilRun  # noqa: E402

DEFAULT_QUOTAS = "exact,none,25,15,10,7.5,5"
# The vehicle's cgroup weighs as much as 100 processes at nice 0: up to its quota, the
# other jobs on this shared machine delay it little (at the default 1024, its 14
# processes together weigh as one, and under a load of 20 it starved unconfined).
SHARES = 102_400


class QuotaHilRun(HilRun):
    """HIL on this machine with the vehicle in ``quota`` and a second ground endpoint for
    the watcher (both processes inherit this one's niceness)."""

    def __init__(
        self, tmp: Path, quota: CpuQuota, watch_port: int, *hil_args: str, composed: bool = False
    ) -> None:
        self.quota, self.watch_port = quota, watch_port
        super().__init__(tmp, *hil_args, composed=composed)

    def _start(
        self, name: str, env: dict[str, str], *args: str, new_session: bool = False
    ) -> subprocess.Popen[str]:
        vehicle = name.startswith("vehicle")
        if vehicle:  # the watcher listens as a second ground station (MAVSDK has the first)
            ours = f'"udpout://127.0.0.1:{self.port}"'
            theirs = f'{ours}, "udpout://127.0.0.1:{self.watch_port}"'
            self.config.write_text(self.config.read_text().replace(ours, theirs))

        # The vehicle joins before it starts its plug-ins: they are all confined with it.
        before_exec = self.quota.join if vehicle else None
        with (self.tmp / f"{name}.log").open("w") as out:
            cmd = [sys.executable, "-m", "companion", *args]
            return subprocess.Popen(cmd, cwd=REPO, env=env, text=True, stdout=out, stderr=out,
                                    preexec_fn=before_exec,
                                    start_new_session=new_session)  # fmt: skip


def _line_drops(report: str) -> dict[str, int]:
    """The simulator's last report: bytes each line could not hand over."""
    return {k: int(n) for k, n in re.findall(r"(\w+) \d+B \((\d+) dropped\)", report)}


LAYOUTS = {False: "one process per plug-in", True: "composed"}


def fly_quota(
    percent: float | None, plan: Path, deadline_s: float, renice: dict, composed: bool = False
) -> dict:
    """One real-time HIL flight with the vehicle in ``percent`` of a core (None: no limit);
    ``composed``: its plug-ins in one process."""
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp, CpuQuota(percent, shares=SHARES) as quota:
        watch = Watch(renice)
        hil_args = ("--duration", str(deadline_s + 120))
        run = QuotaHilRun(Path(tmp), quota, watch.port, *hil_args, composed=composed)
        watch.start_on(run.namespace)
        started, used0 = time.monotonic(), quota.used_s()
        seen: dict = {"finished": False}
        lands = plan_lands(str(plan))
        try:
            seen = asyncio.run(fly_watched(run.port, str(plan), deadline_s, watch, lands))
        except Exception as exc:  # a refusal or a timeout is this row's result, not the end
            seen["error"] = f"{type(exc).__name__}: {exc}"[:120]
            watch.event(seen["error"])
        finally:
            wall = time.monotonic() - started
            used, throttled = quota.used_s() - used0, quota.throttled()
            watch.stop()
            quota.close()  # unconfined, the vehicle stops at once
            try:
                run.stop()
            except Exception as exc:  # it is ended either way; the row says so
                watch.event(f"stopping: {exc!r}")
        row = _score(run.truth, plan, seen)
        if lands:
            row.update(_landing(run.truth, plan))
        reports = [ln for ln in run.log("hil").splitlines() if " out: " in ln]
        drops = _line_drops(reports[-1]) if reports else {}
        vehicle_log = run.log("vehicle")
    row.update(watch.summary(seen))
    row.update(cpu_pct=100 * used / wall, throttled_pct=100 * throttled[1] / max(throttled[0], 1),
               imu_line_dropped=drops.get("imu", 0), load=(load0 + os.getloadavg()[0]) / 2,
               period_ms=quota.period_us / 1000)  # fmt: skip
    if not row["first_failure"] and not seen.get("finished"):
        row["first_failure"] = _last_error(vehicle_log) or seen.get("error", "not finished")
    return row


def _score(truth: Path, plan: Path, seen: dict) -> dict:
    try:
        score = score_track(read_estimate(truth), plan, "c172p").as_row()
    except (OSError, ValueError, KeyError) as exc:
        seen.setdefault("error", f"no truth to score: {exc}")
        score = {"xtrack_rms_m": np.nan, "xtrack_p95_m": np.nan, "alt_rms_m": np.nan}
    return {"completed": bool(seen.get("finished")), **score}


def _landing(truth: Path, plan: Path) -> dict:
    """The touchdown of a plan that ends in a landing, scored as benchmarks/landing.py
    scores it."""
    try:
        items = checked_plan(plan)[0]
        return {"landing": landing_score_for_plan(read_truth(truth), items)}
    except (OSError, KeyError, ValueError) as exc:  # no truth, or a truth cut short
        return {"landing": LandingScore(False), "landing_error": str(exc)[:80]}


def format_landing(s: LandingScore | None) -> str | None:
    """The row's landing, one line (None: the plan has none)."""
    if s is None:
        return None
    if not s.landed:
        return "       landing: none"
    verdict = "on target" if s.passed() else "MISSED"
    return (f"       landing: {s.along_m:+.1f} m along, {s.across_m:+.2f} m across, "
            f"sink {s.sink_m_s:.2f} m/s, bounce {s.bounce_m:.2f} m, stopped {s.stopped}: "
            f"{verdict}")  # fmt: skip


def _last_error(log_text: str) -> str:
    errors = [ln for ln in log_text.splitlines() if " ERROR " in ln or "Traceback" in ln]
    return errors[0][-120:] if errors else ""


def fly_exact(plan: Path) -> dict:
    """The reference: the same plan in exact lockstep (no quota, simulation time)."""
    flight = Flight(str(plan), "c172p", (0.0, 0.0, 0.0), "none", (), 1, str(SIM_CONFIG),
                    False, 900.0, 10.0)  # fmt: skip
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        row = fly_flight(FlightJob(flight, tmp, timeout_s=1800.0))
    row["load"] = (load0 + os.getloadavg()[0]) / 2
    row["first_failure"] = row.get("error", "")
    return row


HEADER = (
    f"{'quota':>6} {'period':>6} {'done':5} {'xt rms':>6} {'xt p95':>6} {'alt rms':>7} "
    f"{'servo p50/p99 ms':>16} {'imu Hz':>6} {'nav Hz':>6} {'ctl Hz':>6} {'ATT Hz':>6} "
    f"{'GPI Hz':>6} "
    f"{'dropped':>7} {'bad':>5} {'imu B lost':>10} {'CPU %':>6} {'thr %':>5} {'load':>5}"
    "  first failure"
)


def _fmt(row: dict, key: str, spec: str, width: int) -> str:
    value = row.get(key)
    return f"{value:{width}{spec}}" if isinstance(value, int | float) else f"{'-':>{width}}"


def format_row(label: str, row: dict) -> str:
    """One line of the table; ``-`` where the row has no such figure (lockstep)."""
    lat = (f"{row['servo_p50_ms']:.1f} / {row['servo_p99_ms']:.1f}"
           if "servo_p50_ms" in row else "-")  # fmt: skip
    return " ".join([
        f"{label:>6}", _fmt(row, "period_ms", ".1f", 6), f"{row['completed']!s:5}",
        _fmt(row, "xtrack_rms_m", ".2f", 6), _fmt(row, "xtrack_p95_m", ".2f", 6),
        _fmt(row, "alt_rms_m", ".2f", 7), f"{lat:>16}", _fmt(row, "imu_hz", ".1f", 6),
        _fmt(row, "nav_hz", ".1f", 6), _fmt(row, "ctl_hz", ".1f", 6),
        _fmt(row, "att_hz", ".1f", 6), _fmt(row, "gpi_hz", ".1f", 6),
        _fmt(row, "dropped", "d", 7), _fmt(row, "bad", "d", 5),
        _fmt(row, "imu_line_dropped", "d", 10), _fmt(row, "cpu_pct", ".1f", 6),
        _fmt(row, "throttled_pct", ".0f", 5), _fmt(row, "load", ".1f", 5),
        f" {row.get('first_failure') or '-'}",
    ])  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plan", default="square.plan", help="a qgc_plans name or a path")
    ap.add_argument(
        "--quotas",
        default=DEFAULT_QUOTAS,
        help="percent of one core, comma-separated; none: no quota; exact: lockstep",
    )
    ap.add_argument("--deadline", type=float, default=600.0, help="seconds per flight")
    ap.add_argument("--quick", action="store_true", help="short_leg.plan at 15 %% only")
    ap.add_argument(
        "--nice",
        type=int,
        default=-10,
        help="niceness of the simulator, the vehicle and this watcher (0: as is)",
    )
    ap.add_argument("--health", action="store_true", help="print each plug-in's counters too")
    ap.add_argument("--renice", default="", help="NAME=NICE,... plug-ins reniced once up")
    ap.add_argument(
        "--composed", action="store_true", help="every plug-in in one process (aircraft.toml's)"
    )
    args = ap.parse_args()
    # The simulator, the vehicle, MAVSDK and the exact row's processes inherit it.
    os.nice(args.nice)
    if args.quick:
        args.plan, args.quotas = "short_leg.plan", "15"
    plan = Path(args.plan).resolve() if Path(args.plan).exists() else PLANS / args.plan
    renice = {k: int(v) for k, v in (p.split("=") for p in args.renice.split(",") if p)}
    quotas = [q.strip() for q in args.quotas.split(",") if q.strip()]
    reason = unusable_reason()
    if reason and any(q != "exact" for q in quotas):
        sys.exit(f"cpu_quota: {reason}")
    print(
        f"c172p {plan.name}, calm, {LAYOUTS[args.composed]}; quota = % of one core; "
        f"{os.cpu_count()} cores "
        f"shared with other jobs (load = 1-min load average during the row); simulator and "
        f"watcher at nice {args.nice}, the vehicle's cgroup at cpu.shares {SHARES}",
        flush=True,
    )
    print(HEADER, flush=True)
    for q in quotas:
        if q == "exact":
            row = fly_exact(plan)
        else:
            limit = None if q == "none" else float(q)
            row = fly_quota(limit, plan, args.deadline, renice, args.composed)
        print(format_row(q, row), flush=True)
        if (landed := format_landing(row.get("landing"))) is not None:
            print(landed, flush=True)
        if args.health:
            for name, h in row.get("health", {}).items():
                print(
                    f"       {name:10} CPU {h['cpu_pct']:5.1f} %  dropped {h['dropped']}  "
                    f"bad {h['frames_bad']}  restarts {h['restarts']}  "
                    f"step p50 {h['step_p50_us']:.0f} µs",
                    flush=True,
                )


if __name__ == "__main__":
    main()
