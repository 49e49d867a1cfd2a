"""What killing each plug-in in flight costs: output gap, the navigator's jump, excursion.

Usage: uv run python benchmarks/crash_recovery.py [--plan square_3km.plan] [--every 8]
       [--only nav,link] [--no-supervisor]

Hardware in the loop (tests/support/hil.py: ``companion hil`` and ``companion run`` apart,
real time), so the aircraft flies on while the vehicle's processes die. The plan is flown
with MAVSDK; each plug-in is killed with SIGKILL in turn, at least ``--every`` seconds
apart, each time on a leg's straight part (from the controller's distance to its
waypoint: 3 km legs leave room for the window after the kill), then ``companion run``
itself, which is started again at once as its service would. Per plug-in it prints:
- ``gap``: from the kill until the plug-in's output channel carries a new sample (for the
  supervisor: until the vehicle is armed in Mission again, as MAVSDK sees it);
- ``nav jump``: for the navigator, how far its first solution after the restart lies from
  the last one before, less the motion in between (attitude in degrees, position in m);
- ``excursion``: how much further off its leg the aircraft was in the 8 s after the kill
  (after the supervisor's: after it is back) than at the kill, across and in height, from
  the simulator's truth (the logger's gap is the plug-in statistics it publishes, the only
  output it has);
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
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.plugins.telemetry import FlightMode

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from companion.bus.node import BusNode  # noqa: E402
from companion.control.mission.plan import checked_plan  # noqa: E402
from companion.geodesy import LocalFrame  # noqa: E402
from companion.messages import NavFlags  # noqa: E402
from companion.navigation.estimate_csv import read_estimate  # noqa: E402
from ground.campaign.legs import STRAIGHT_MARGIN_M, flight_legs  # noqa: E402
from tests.support.hil import HilRun  # noqa: E402
from tests.support.mavsdk_flight import plan_uploaded  # noqa: E402

# Each plug-in of the HIL config and the channel its work shows on.
OUTPUT = {
    "commander": "vehicle/status", "control": "control/actuators", "servos": "actuators/servos",
    "nav": "nav/state", "imu": "sensors/imu", "gps": "sensors/gps", "compass": "sensors/compass",
    "rc": "sensors/rc", "battery": "sensors/battery", "range": "sensors/range",
    "logger": "system/plugin_stats", "link": "link/status",
}  # fmt: skip
SUPERVISOR = "supervisor"
WINDOW_S = 8.0
PLANS = REPO / "benchmarks" / "plans"
# A kill only where the leg's straight part lasts past the window: so far from the
# waypoint behind and the one ahead (36 m/s for WINDOW_S, and a margin).
FROM_CORNER_M = STRAIGHT_MARGIN_M + 100.0
BEFORE_CORNER_M = STRAIGHT_MARGIN_M + 36.0 * WINDOW_S + 100.0


class Watch(threading.Thread):
    """Records when each output channel carries a new sample (wall time), nav/state, and
    the controller's newest status (which leg, how far to its waypoint)."""

    def __init__(self, namespace: str) -> None:
        super().__init__(daemon=True)
        self.bus = BusNode(namespace, "crash_bench")
        self.readers = {ch: self.bus.reader(ch) for ch in OUTPUT.values()}
        self.control = self.bus.latest_reader("control/status")
        self.seen: dict[str, list[float]] = {ch: [] for ch in OUTPUT.values()}
        self.nav: list[tuple[float, object]] = []
        self.last: dict[str, int] = {}
        self.stop = False

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

    def on_a_straight(self, leg_m: float) -> bool:
        """The aircraft flies a square's leg (past the first waypoint), far from both ends."""
        status = self.control.get()
        if status is None or status.mission_seq < 2 or not math.isfinite(status.wp_dist_m):
            return False
        return BEFORE_CORNER_M < status.wp_dist_m < leg_m - FROM_CORNER_M

    def gap_s(self, channel: str, killed: float) -> float:
        after = [t for t in self.seen[channel] if t > killed + 0.01]
        return after[0] - killed if after else math.inf


def _leg_m(plan: Path) -> float:
    """The square's side (its second and third waypoints apart)."""
    items = checked_plan(plan)[0]
    frame = LocalFrame(items[1].x / 1e7, items[1].y / 1e7)
    return math.hypot(*frame.ne(items[2].x / 1e7, items[2].y / 1e7))


async def _first(stream):  # type: ignore[no-untyped-def]
    async for value in stream:
        return value
    return None


async def _back_in_mission(telemetry: TelemetryAsync, since: float) -> float:
    """Seconds from ``since`` until MAVSDK sees the vehicle armed in Mission again."""
    while time.monotonic() - since < 60.0:
        # Both from the same (1 Hz) heartbeat: asked one after the other, each would wait
        # for the next one, adding up to a second to the figure.
        armed, mode = await asyncio.gather(
            _first(telemetry.subscribe_armed()), _first(telemetry.subscribe_flight_mode())
        )
        if armed and mode == FlightMode.MISSION:
            return time.monotonic() - since
        await asyncio.sleep(0.05)
    return math.inf


async def _killer(run: HilRun, watch: Watch, telemetry: TelemetryAsync, opts: dict) -> None:
    for name in opts["victims"]:
        await asyncio.sleep(opts["every"])
        while not watch.on_a_straight(opts["leg_m"]):
            await asyncio.sleep(0.1)
        if name == SUPERVISOR:
            run.vehicle.send_signal(signal.SIGKILL)
            run.vehicle.wait()
            opts["kills"][name] = killed = time.monotonic()
            run.restart_vehicle()  # at once, as its service would
            opts["back_s"] = await _back_in_mission(telemetry, killed)
            continue
        kids = psutil.Process(run.vehicle.pid).children(recursive=True)
        pid = next((k.pid for k in kids if k.name() == name), None)
        if pid is not None:
            os.kill(pid, signal.SIGKILL)
            opts["kills"][name] = time.monotonic()


async def _fly_with_kills(run: HilRun, watch: Watch, plan: Path, opts: dict) -> dict:
    async with plan_uploaded(run.port, str(plan)) as flight:
        telemetry, mission = flight.telemetry, flight.mission
        await flight.action.arm()
        await mission.start_mission()
        task = asyncio.ensure_future(_killer(run, watch, telemetry, opts))
        modes: set = set()
        stop = time.monotonic() + 900.0
        while time.monotonic() < stop and not await mission.is_mission_finished():
            modes.add(await _first(telemetry.subscribe_flight_mode()))
            await asyncio.sleep(0.5)
        finished = await mission.is_mission_finished()
        task.cancel()
    return {"finished": finished, "modes": modes}


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
    up = (b.alt_msl_m - a.alt_msl_m) + a.vd_m_s * dt
    turned = [math.degrees(abs(math.remainder(getattr(b, k) - getattr(a, k), math.tau)))
              for k in ("roll_rad", "pitch_rad", "yaw_rad")]  # fmt: skip
    return f"{turned[0]:.1f}/{turned[1]:.1f}/{turned[2]:.1f}° {moved:.1f} m, {up:+.1f} m up"


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


def _sim_offset_s(truth: dict, watch: Watch, started: float) -> float:
    """Simulated time less the wall time since ``started``: the simulator starts its clock
    after it has loaded (seconds, under load), so the truth is matched to the navigator's
    positions (the aircraft moves 36 m in a second: a match is good to ~0.1 s)."""
    lat, lon, t = (np.asarray(truth[k], dtype=float) for k in ("lat", "lon", "t"))
    frame = LocalFrame(float(lat[0]), float(lon[0]))
    north, east = frame.ne(lat, lon)
    offsets = []
    for wall, nav in watch.nav[:: max(1, len(watch.nav) // 50)]:
        if not _attitude_valid(nav):
            continue
        n, e = frame.ne(nav.lat_deg, nav.lon_deg)  # type: ignore[attr-defined]
        offsets.append(t[int(np.argmin(np.hypot(north - n, east - e)))] - (wall - started))
    return float(np.median(offsets)) if offsets else 0.0


def _failsafes(log: str, killed_wall: float, window_s: float) -> str:
    """Failsafe lines the vehicle logged in the window after a kill (wall clock)."""
    texts = []
    for line in log.splitlines():
        m = re.match(r"\d{4}-\d\d-\d\d (\d\d):(\d\d):(\d\d),(\d{3}) .*(Failsafe[^\n]*)", line)
        if m is None:
            continue
        h, mi, s, ms = (int(v) for v in m.groups()[:4])
        t = h * 3600 + mi * 60 + s + ms / 1000
        if 0 <= t - killed_wall <= window_s:
            texts.append(m.group(5)[:40])
    return "; ".join(texts) or "none"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plan", default="square_3km.plan")
    ap.add_argument("--every", type=float, default=8.0, help="seconds at least between kills")
    ap.add_argument("--only", default="", help="comma-separated plug-ins (default: all)")
    ap.add_argument("--no-supervisor", action="store_true", help="leave companion run alive")
    args = ap.parse_args()
    plan = Path(args.plan) if Path(args.plan).exists() else PLANS / args.plan
    victims = [v for v in args.only.split(",") if v] or list(OUTPUT)
    victims += [] if args.no_supervisor else [SUPERVISOR]
    opts = {"victims": victims, "every": args.every, "leg_m": _leg_m(plan), "kills": {}}
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "kills").mkdir()
        run = HilRun(Path(tmp) / "kills", "--duration", "1200")
        watch: Watch | None = None
        try:
            watch = Watch(run.namespace)
            watch.start()
            flown = asyncio.run(_fly_with_kills(run, watch, plan, opts))
        finally:
            if watch is not None:
                watch.stop = True
                watch.join()
                watch.bus.close()
            run.stop()
        _report(run, plan, watch, flown, opts)


def _report(run: HilRun, plan: Path, watch: Watch, flown: dict, opts: dict) -> None:
    truth = read_estimate(run.truth)
    t, across, height = _off_the_plan(truth, plan)
    offset = _sim_offset_s(truth, watch, run.started)
    log = run.log("vehicle") + (run.log("vehicle_restarted") if SUPERVISOR in opts["kills"] else "")
    wall = time.time() - time.monotonic()  # monotonic -> wall clock, for the log's stamps
    modes = sorted(str(m) for m in flown["modes"])
    print(f"plan {plan.name}; mission finished: {flown['finished']}; modes seen: {modes}")
    print(f"load average: {os.getloadavg()}; simulated time = wall time + {offset:.2f} s")
    print("excursion: the most the aircraft was off its leg's straight part in the 8 s after")
    print("the kill (the supervisor: after it is back), less how far off it was at the kill")
    print("| plug-in | back after | nav jump (roll/pitch/yaw, across, up) |", end="")
    print(" across | height | failsafe |")
    print("|---|---|---|---|---|---|")
    for name, killed in opts["kills"].items():
        if name == SUPERVISOR:
            gap = opts.get("back_s", math.inf)
        else:
            gap = watch.gap_s(OUTPUT[name], killed)
        k = killed - run.started + offset  # the simulated second of the kill
        at = min(int(np.searchsorted(t, k)), len(t) - 1)
        window = WINDOW_S + (gap if name == SUPERVISOR and math.isfinite(gap) else 0.0)
        win = (t >= k) & (t <= k + window)
        dx, dz = (_worse(e[win], e[at]) for e in (across, height))
        jump = _nav_jump(watch, killed) if name in ("nav", SUPERVISOR) else "-"
        fs = _failsafes(log, _seconds_of_day(killed + wall), window)
        print(f"| {name} | {gap:.2f} s | {jump} | {dx:.1f} m | {dz:.1f} m | {fs} |")


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
