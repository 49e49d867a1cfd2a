"""What killing each plug-in in flight costs: output gap, the navigator's jump, excursion.

Usage: uv run python benchmarks/crash_recovery.py [--plan square.plan] [--every 8]

Hardware in the loop (tests/support/hil.py: ``companion hil`` and ``companion run`` apart,
real time), so the aircraft flies on while the vehicle's processes die. The plan is flown
with MAVSDK, each plug-in killed with SIGKILL in turn, ``--every`` seconds apart from
``--from`` seconds after the mission started. Per plug-in it prints:
- ``gap``: from the kill until the plug-in's output channel carries a new sample;
- ``nav jump``: for the navigator, how far its first solution after the restart lies from
  the last one before, less the motion in between (attitude in degrees, position in m);
- ``excursion``: how much further off its leg the aircraft was in the 8 s after the kill
  than at the kill, across and in height, from the simulator's truth (the logger's gap is
  the plug-in statistics it publishes, the only output it has);
- ``failsafe``: the failsafe texts the vehicle logged in that window.
Real time on a shared machine: figures move with the load (print ``uptime`` beside them).
"""

from __future__ import annotations

import argparse
import asyncio
import math
import os
import re
import signal
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import psutil

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from companion.bus.node import BusNode  # noqa: E402
from companion.control.mission.plan import checked_plan  # noqa: E402
from companion.geodesy import LocalFrame  # noqa: E402
from companion.messages import NavFlags, channel  # noqa: E402
from companion.navigation.estimate_csv import read_estimate  # noqa: E402
from ground.campaign.legs import flight_legs  # noqa: E402
from ground.campaign.spec import PLANS  # noqa: E402
from tests.support.hil import HilRun  # noqa: E402
from tests.support.mavsdk_flight import fly_plan  # noqa: E402

# Each plug-in of the HIL config and the channel its work shows on.
OUTPUT = {
    "commander": "vehicle/status", "control": "control/actuators", "servos": "actuators/servos",
    "nav": "nav/state", "imu": "sensors/imu", "gps": "sensors/gps", "compass": "sensors/compass",
    "rc": "sensors/rc", "battery": "sensors/battery", "range": "sensors/range",
    "logger": "system/plugin_stats", "link": "link/status",
}  # fmt: skip
WINDOW_S = 8.0


class Watch(threading.Thread):
    """Records when each output channel carries a new sample (wall time), and nav/state."""

    def __init__(self, namespace: str) -> None:
        super().__init__(daemon=True)
        self.bus = BusNode(namespace, "crash_bench")
        self.readers = {ch: self._reader(ch) for ch in OUTPUT.values()}
        self.seen: dict[str, list[float]] = {ch: [] for ch in OUTPUT.values()}
        self.nav: list[tuple[float, object]] = []
        self.last: dict[str, int] = {}
        self.stop = False

    def _reader(self, name: str):  # type: ignore[no-untyped-def]
        if channel(name).pattern == "latest":
            return self.bus.latest_reader(name)
        return self.bus.queue_reader(name)

    def run(self) -> None:
        while not self.stop:
            now = time.monotonic()
            for ch, reader in self.readers.items():
                samples = [reader.get()] if hasattr(reader, "get") else list(reader.drain())
                for sample in samples:
                    if sample is None or self.last.get(ch) == int(sample.t_us):
                        continue
                    self.last[ch] = int(sample.t_us)
                    self.seen[ch].append(now)
                    if ch == "nav/state":
                        self.nav.append((now, sample))
            time.sleep(0.002)

    def gap_s(self, channel: str, killed: float) -> float:
        after = [t for t in self.seen[channel] if t > killed + 0.01]
        return after[0] - killed if after else math.inf


async def _fly_with_kills(run: HilRun, plan: Path, start_s: float, every_s: float) -> dict:
    kills: dict[str, float] = {}

    async def killer() -> None:
        await asyncio.sleep(start_s + 15.0)  # arming and the climb-out come first
        for name in OUTPUT:
            kids = psutil.Process(run.vehicle.pid).children(recursive=True)
            pid = next((k.pid for k in kids if k.name() == name), None)
            if pid is not None:
                os.kill(pid, signal.SIGKILL)
                kills[name] = time.monotonic()
            await asyncio.sleep(every_s)

    task = asyncio.ensure_future(killer())
    seen = await fly_plan(run.port, str(plan), 600.0)
    task.cancel()
    return {"seen": seen, "kills": kills}


def _attitude_valid(nav: object) -> bool:
    return bool(nav.flags & NavFlags.ATTITUDE_VALID) and math.isfinite(nav.roll_rad)  # type: ignore[attr-defined]


def _nav_jump(watch: Watch, killed: float) -> str:
    before = [s for t, s in watch.nav if t < killed]
    after = [s for t, s in watch.nav if t > killed + 0.01 and _attitude_valid(s)]
    if not before or not after:
        return "-"
    a, b = before[-1], after[0]
    dt = (b.t_us - a.t_us) / 1e6
    frame = LocalFrame(a.lat_deg, a.lon_deg)
    n, e = frame.ne(b.lat_deg, b.lon_deg)
    moved = math.hypot(n - a.vn_m_s * dt, e - a.ve_m_s * dt)
    turned = [math.degrees(abs(math.remainder(getattr(b, k) - getattr(a, k), math.tau)))
              for k in ("roll_rad", "pitch_rad", "yaw_rad")]  # fmt: skip
    return f"{turned[0]:.1f}/{turned[1]:.1f}/{turned[2]:.1f}° {moved:.1f} m"


def _off_the_plan(truth: dict, plan: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sim time, |cross-track| and |height error| of each truth sample on the straight part
    of the leg it flew (NaN elsewhere: the climb, the corners)."""
    columns = {k: np.asarray(v, dtype=float) for k, v in truth.items()}
    t = columns["t"]
    across, height = np.full(len(t), np.nan), np.full(len(t), np.nan)
    for figures in flight_legs(columns, checked_plan(plan)[0], "c172p"):
        track = figures.track
        rows = np.arange(track.i0, track.i1)[track.straight()]  # corners would count as errors
        across[rows] = np.abs(track.cross[track.straight()])
        height[rows] = np.abs(columns["alt"][rows] - track.leg.alt_msl)
    return t, across, height


def _failsafes(log: str, killed_wall: float) -> str:
    """Failsafe lines the vehicle logged in the window after a kill (wall clock)."""
    texts = []
    for line in log.splitlines():
        m = re.match(r"\d{4}-\d\d-\d\d (\d\d):(\d\d):(\d\d),(\d{3}) .*(Failsafe[^\n]*)", line)
        if m is None:
            continue
        h, mi, s, ms = (int(v) for v in m.groups()[:4])
        t = h * 3600 + mi * 60 + s + ms / 1000
        if 0 <= t - killed_wall <= WINDOW_S:
            texts.append(m.group(5)[:40])
    return "; ".join(texts) or "none"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plan", default="square.plan")
    ap.add_argument("--every", type=float, default=8.0, help="seconds between kills")
    ap.add_argument("--from", dest="start", type=float, default=40.0, help="first kill (s)")
    args = ap.parse_args()
    plan = Path(args.plan) if Path(args.plan).exists() else PLANS / args.plan
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "kills").mkdir()
        run = HilRun(Path(tmp) / "kills", "--duration", "900")
        watch: Watch | None = None
        try:
            watch = Watch(run.namespace)
            watch.start()
            flown = asyncio.run(_fly_with_kills(run, plan, args.start, args.every))
        finally:
            if watch is not None:
                watch.stop = True
                watch.join()
                watch.bus.close()
            run.stop()
        _report(run, plan, watch, flown)


def _report(run: HilRun, plan: Path, watch: Watch, flown: dict) -> None:
    t, across, height = _off_the_plan(read_estimate(run.truth), plan)
    log = run.log("vehicle")
    wall = time.time() - time.monotonic()  # monotonic -> wall clock, for the log's stamps
    print(f"mission finished: {flown['seen'].get('finished')}  load: {os.getloadavg()}")
    print("excursion: the most the aircraft was off its leg in the 8 s after the kill, less")
    print("how far off it was at the kill (m; NaN: not on a leg's straight part then)")
    print(f"{'plug-in':10} {'gap':>7} {'nav jump':>22} {'across':>8} {'height':>8}  failsafe")
    for name, killed in flown["kills"].items():
        k = killed - run.started  # about the simulated second of the kill
        at = min(int(np.searchsorted(t, k)), len(t) - 1)
        win = (t >= k) & (t <= k + WINDOW_S)
        dx, dz = (_worse(e[win], e[at]) for e in (across, height))
        jump = _nav_jump(watch, killed) if name == "nav" else "-"
        fs = _failsafes(log, _seconds_of_day(killed + wall))
        gap = watch.gap_s(OUTPUT[name], killed)
        print(f"{name:10} {gap:6.2f}s {jump:>22} {dx:7.1f}m {dz:7.1f}m  {fs}")


def _worse(window: np.ndarray, at_kill: float) -> float:
    """How much the error grew in the window (NaN when not measurable)."""
    if not np.isfinite(at_kill) or not np.isfinite(window).any():
        return math.nan
    return float(np.nanmax(window) - at_kill)


def _seconds_of_day(epoch_s: float) -> float:
    lt = time.localtime(epoch_s)
    return lt.tm_hour * 3600 + lt.tm_min * 60 + lt.tm_sec + epoch_s % 1


if __name__ == "__main__":
    main()
