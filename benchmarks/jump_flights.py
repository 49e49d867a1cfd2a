"""How benchmarks/jump_landings.py flies a plan besides ``companion sim``: a watcher that
kills the control plug-in on the loop's second lap, and the control laws alone.
"""

from __future__ import annotations

import math
import os
import signal
import threading
import time
from pathlib import Path

import psutil

from companion.bus.namespace import cleanup_namespace
from companion.bus.node import BusNode
from companion.control.flight.landing_flight import approach_start
from companion.control.mission.plan import checked_plan
from ground.campaign.landing_score import landing_score_for_plan
from mavlink_dialect import companion as d
from tests.support.closed_loop import ClosedLoop


def _second_lap(plan: Path) -> int:
    """How many items are reached when the loop's second lap has begun (its first item)."""
    from benchmarks.jump_landings import planned_order

    order = planned_order(plan)
    items = checked_plan(plan)[0]
    jump = next(it for it in items if it.command == d.MAV_CMD_DO_JUMP)
    target = next(s for s in order if s >= round(jump.param1))
    return [k for k, s in enumerate(order) if s == target][1] + 1


class ControlKiller:
    """Kills this process's flight's ``control`` plug-in once (SIGKILL), on the loop's
    second lap, as a crash would; the execution control starts it again."""

    def __init__(self, plan: Path) -> None:
        self.after = _second_lap(plan)
        self.stop = threading.Event()
        self.killed_at: int | None = None  # the item flown to when it was killed
        self.namespace: str | None = None

    def run(self) -> None:
        while not self.stop.wait(0.5) and self.namespace is None:
            self.namespace = self._find()
        if self.namespace is None:
            return
        bus = BusNode(self.namespace, "killer")
        control = bus.latest_reader("control/status")
        try:
            while not self.stop.wait(0.02):
                status = control.get()
                if status is not None and status.reached_count >= self.after:
                    pid = self._pid("control")
                    if pid is not None:
                        os.kill(pid, signal.SIGKILL)
                        self.killed_at = status.mission_seq
                        return
        finally:
            bus.close()
            cleanup_namespace(self.namespace)

    def _find(self) -> str | None:
        token = f"camp{os.getpid()}p"
        for proc in psutil.process_iter(["cmdline"]):
            cmd = proc.info["cmdline"] or []
            for k, arg in enumerate(cmd[:-1]):
                if arg == "--namespace" and cmd[k + 1].startswith(token):
                    return cmd[k + 1]
        return None

    def _pid(self, name: str) -> int | None:
        token = f"--namespace {self.namespace} "
        for proc in psutil.process_iter(["name", "cmdline"]):
            if proc.info["name"] == name and token in " ".join(proc.info["cmdline"] or []) + " ":
                return proc.pid
        time.sleep(0.01)
        return None


def fly_closed_loop(plan: Path, airframe: str, weather: tuple, seed: int) -> tuple[bool, str]:
    """The control laws alone against JSBSim on the true state; judged as the whole
    vehicle's flights are, on the items the controller reached."""
    from benchmarks.jump_landings import (
        SAFE_SHARE,
        _landing_first,
        back_to_zero,
        least_planned,
        planned_order,
    )

    items = checked_plan(plan)[0]
    wind, turbulence = weather
    loop = ClosedLoop(airframe, items, wind_ned=wind, turbulence=turbulence, range_max_m=12.0)
    loop.flight.fdm["atmosphere/randomseed"] = seed + 2
    disarmed = loop.fly_until_disarmed(2000.0)
    order = planned_order(plan)
    seqs = [s.out.mission_seq for s in loop.samples]
    score = landing_score_for_plan(loop.truth(), items)
    faults = []
    if not reached_as_planned(loop.reached, order, items):  # the link tells each
        faults.append(f"reached {loop.reached} != {order}")
    if back_to_zero(seqs, order):
        faults.append("MISSION_CURRENT back to 0")
    low = _lowest(loop, items, order, seqs, _landing_first(items, order))
    if not low >= SAFE_SHARE * least_planned(items, order):
        faults.append(f"down to {low:.0f} m before the landing")
    if not score.passed():
        faults.append("landing off target")
    if not disarmed:
        faults.append("not disarmed")
    text = (f"{score.along_m:+7.1f} / {score.across_m:+5.2f} m sink {score.sink_m_s:4.2f} "
            f"low {low:4.0f} m")  # fmt: skip
    return not faults, text + ("  " + "; ".join(faults) if faults else "")


def _lowest(loop: ClosedLoop, items: list, order: list, seqs: list, landing: int) -> float:
    began = landing_began(seqs, landing, last_land(items, order))
    if order[1] not in seqs or began is None:
        return math.nan
    climbed = seqs.index(order[1]) + 50 * 20  # 20 s after the take-off item
    heights = [s.alt_agl for s in loop.samples[climbed:began]]
    return min(heights) if heights else math.nan


def last_land_at(items: list, order: list[int]) -> int:
    """Where in ``order`` the plan flies its last NAV_LAND (-1: none)."""
    lands = [k for k, s in enumerate(order) if items[s].command == d.MAV_CMD_NAV_LAND]
    return lands[-1] if lands else -1


def last_land(items: list, order: list[int]) -> int:
    """The seq of the last NAV_LAND the plan flies (-1: none)."""
    at = last_land_at(items, order)
    return order[at] if at >= 0 else -1


def reached_as_planned(reached: list[int], order: list[int], items: list) -> bool:
    """Whether the items reached are the plan's order, a go-around allowed for: it flies the
    landing's approach again (from DO_LAND_START, else the item before the NAV_LAND:
    ``approach_start``), whose items are then reached once more."""
    if reached == order:
        return True
    j = last_land_at(items, order)
    if j < 0:
        return False
    restart, k = approach_start(items, order[j]), j
    while k > 0 and order[k - 1] >= restart:
        k -= 1
    again = order[k:j]
    return any(reached == order[:k] + again * (1 + n) + order[j:] for n in range(1, 4))


def landing_began(seqs: list[int], landing: int, land: int) -> int | None:
    """Where in ``seqs`` (the current item, in order) the landing began: the last stretch
    of ``landing`` (the item flown before the NAV_LAND ``land``) before the NAV_LAND is
    first current. A go-around's climb and second approach come after it."""
    end = seqs.index(land) if land in seqs else len(seqs)
    runs = [k for k in range(end) if seqs[k] == landing]
    if not runs:
        return None
    k = runs[-1]
    while k > 0 and seqs[k - 1] == landing:
        k -= 1
    return k
