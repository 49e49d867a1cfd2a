"""Crashes in exact lockstep: a plan is flown while a script kills each plug-in in turn.

``companion sim --exact`` holds the simulation for the vehicle's drivers and its control
loop, so a killed plug-in costs no simulated time it would not cost in the air, and the
flight scores the same on a loaded machine. Each plug-in is killed with SIGKILL once, on a
leg's straight part (the controller's distance to its waypoint says where), one every few
simulated seconds; the execution control starts it again. The flight is then scored on
the simulator's truth: the mission completed (its last item, Return, reached), in Mission
until then, no failsafe, the track on every leg's straight part within 2 m across and 10 m
in height.
"""

from __future__ import annotations

import itertools
import logging
import os
import signal
import subprocess
import threading

import numpy as np
import psutil
import pytest

from companion.bus.namespace import cleanup_namespace
from companion.bus.node import BusNode
from companion.control.mission.plan import checked_plan
from companion.geodesy import LocalFrame
from companion.link.codec import dialect as d
from companion.messages import FlightMode
from companion.navigation.estimate_csv import read_estimate as read_truth
from ground.campaign.legs import STRAIGHT_MARGIN_M
from tests.protocol.mav_client import free_udp_port
from tests.sim.sim_run import SimRun, finish, start_sim
from tests.support.vehicle import REPO

PLAN = REPO / "qgc_plans" / "square.plan"
RETURN_SEQ = len(checked_plan(PLAN)[0]) - 1  # the plan ends on NAV_RETURN_TO_LAUNCH
# Each plug-in killed, in this order, and the channel its work shows on.
OUTPUT = {
    "commander": "vehicle/status", "control": "control/actuators", "servos": "actuators/servos",
    "nav": "nav/state", "imu": "sensors/imu", "gps": "sensors/gps", "compass": "sensors/compass",
    "link": "link/status", "rc": "sensors/rc", "battery": "sensors/battery",
    "range": "sensors/range", "logger": "system/plugin_stats",
}  # fmt: skip
VICTIMS = tuple(OUTPUT)
WINDOW_S = 8.0  # the excursion a kill caused is looked for this long after it
KILL_FROM_S, KILL_EVERY_S = 20.0, 7.0  # simulated seconds
START_AT_S = 2.0  # the simulator arms and starts the mission then
FROM_WAYPOINT_M = 400.0  # past the corner's turn, and the window before the next one
MAX_ACROSS_M, MAX_HEIGHT_M = 2.0, 10.0  # across: 0.63-0.69 m measured (121.7 m before)
log = logging.getLogger(__name__)


class Killer(threading.Thread):
    """Kills the victims in turn, by simulated time, and watches the mode and mission."""

    def __init__(self, proc: SimRun, namespace: str) -> None:
        super().__init__(daemon=True)
        self.proc, self.bus = proc, BusNode(namespace, "killer")
        self.control = self.bus.latest_reader("control/status")
        self.status = self.bus.latest_reader("vehicle/status")
        self.outputs = {ch: self.bus.newest_reader(ch) for ch in OUTPUT.values()}
        self.killed: list[tuple[str, float]] = []
        self.back_s: dict[str, float] = {}  # simulated seconds until its output flowed again
        self.modes: set[FlightMode] = set()
        self.completed = False
        self.stop = threading.Event()

    def run(self) -> None:
        victims = list(VICTIMS)
        next_s = KILL_FROM_S
        while not self.stop.wait(0.02) and self.proc.poll() is None:
            # The status first: the controller's status read after it is as new as the one
            # the commander acted on (the mission's Return follows its item reached).
            status, control = self.status.get(), self.control.get()
            if control is None or status is None:
                continue
            now_s = control.t_us / 1e6
            self.completed |= control.last_reached == RETURN_SEQ
            if status.armed and not self.completed:
                self.modes.add(FlightMode(status.mode))
            far = control.wp_dist_m > FROM_WAYPOINT_M and control.mission_seq >= 1
            self._outputs_back(now_s)
            if victims and now_s >= next_s and far and self._kill(victims[0]):
                self.killed.append((victims.pop(0), now_s))
                next_s = now_s + KILL_EVERY_S
        self.bus.close()

    def _outputs_back(self, now_s: float) -> None:
        for name, killed_s in self.killed:
            sample = self.outputs[OUTPUT[name]].get()
            if name not in self.back_s and sample is not None and sample.t_us > killed_s * 1e6:
                self.back_s[name] = max(0.0, sample.t_us / 1e6 - killed_s)

    def _kill(self, name: str) -> bool:
        kids = psutil.Process(self.proc.pid).children(recursive=True)
        pid = next((k.pid for k in kids if k.name() == name), None)
        if pid is None:  # between a death and its restart: the next look
            return False
        os.kill(pid, signal.SIGKILL)
        return True


def off_the_legs(truth: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Simulated time, |cross-track| and |height error| of the truth on the straight part of
    each waypoint-to-waypoint leg, STRAIGHT_MARGIN_M from either end (NaN elsewhere: the
    corners). The aircraft starts in the air, so the take-off's leg is not flown."""
    columns = {k: np.asarray(v, dtype=float) for k, v in truth.items()}
    t = columns["t"]
    home_alt = float(np.interp(START_AT_S, t, columns["alt"]))  # armed there, in the air
    frame = LocalFrame(float(columns["lat"][0]), float(columns["lon"][0]))
    north, east = frame.ne(columns["lat"], columns["lon"])
    points = [(i.x / 1e7, i.y / 1e7, i.z) for i in checked_plan(PLAN)[0]
              if i.command == d.MAV_CMD_NAV_WAYPOINT]  # fmt: skip
    across, height = np.full(len(t), np.nan), np.full(len(t), np.nan)
    for (lat0, lon0, _), (lat1, lon1, alt) in itertools.pairwise(points):
        a, b = np.array(frame.ne(lat0, lon0)), np.array(frame.ne(lat1, lon1))
        length = float(np.hypot(*(b - a)))
        u = (b - a) / length
        along = (north - a[0]) * u[0] + (east - a[1]) * u[1]
        cross = np.abs((east - a[1]) * u[0] - (north - a[0]) * u[1])
        on = (along > STRAIGHT_MARGIN_M) & (along < length - STRAIGHT_MARGIN_M) & (cross < 300)
        across[on] = cross[on]
        height[on] = np.abs(columns["alt"][on] - (home_alt + alt))
    return t, across, height


def excursions(truth: dict, killed: list[tuple[str, float]]) -> dict[str, tuple[float, float]]:
    """Per kill: the most the aircraft was off its leg's straight part across and in height
    in the WINDOW_S after it (NaN: no straight part in that window)."""
    t, across, height = off_the_legs(truth)
    out = {}
    for name, killed_s in killed:
        window = (t >= killed_s) & (t <= killed_s + WINDOW_S)
        out[name] = tuple(
            float(np.nanmax(e[window])) if np.isfinite(e[window]).any() else float("nan")
            for e in (across, height)
        )
    return out


@pytest.mark.timeout(1500)
def test_a_plan_flies_on_in_lockstep_while_each_plugin_is_killed(tmp_path):
    args = ("--exact", "--plan", str(PLAN), "--airborne", "--start-at", str(START_AT_S),
            "--duration", "240")  # fmt: skip
    proc, namespace, truth_path = start_sim(
        tmp_path, f"udpout://127.0.0.1:{free_udp_port()}", *args
    )
    killer = Killer(proc, namespace)
    killer.start()
    try:
        proc.wait(timeout=1400)
    except subprocess.TimeoutExpired:
        pass  # finish() says so
    finally:
        killer.stop.set()
        killer.join()
    # The watcher's bus node, closed after the vehicle had cleaned its namespace, leaves the
    # namespace's management file behind: the test's own, not the vehicle's.
    cleanup_namespace(namespace)
    out = finish(proc, namespace, 10)
    assert [name for name, _ in killer.killed] == list(VICTIMS), (killer.killed, out[-3000:])
    assert killer.completed, out[-3000:]
    assert killer.modes == {FlightMode.MISSION}, killer.modes
    assert "Failsafe" not in out, [ln for ln in out.splitlines() if "Failsafe" in ln]
    truth = read_truth(truth_path)
    for name, (dx, dz) in excursions(truth, killer.killed).items():
        back = killer.back_s.get(name, float("nan"))
        log.info("| %s | %.2f s | %.1f m | %.1f m |", name, back, dx, dz)
    _, across, height = off_the_legs(truth)
    across, height = across[np.isfinite(across)], height[np.isfinite(height)]
    assert across.size > 1000, "too little of the flight on a leg's straight part to score"
    figures = (float(np.max(across)), float(np.max(height)), float(np.sqrt(np.mean(across**2))))
    log.info("max across %.2f m, max height %.2f m, across RMS %.2f m", *figures)
    assert figures[0] < MAX_ACROSS_M and figures[1] < MAX_HEIGHT_M, figures
