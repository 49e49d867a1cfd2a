"""One campaign flight: ``companion sim --speed max`` with the plan, flown as a ground
station would fly it, watched until the mission completes, then scored from the truth.

Each flight has its own bus namespace, UDP port, state dir and process group, so flights
on one machine never meet; its directory keeps the simulator's log, the truth CSV, the
timeline (mission progress, STATUSTEXTs) and the vehicle's own flight log
(``flight.ulg``, for ``companion replay`` and the ULog tools, also when the flight
failed). A flight that dies, stalls or runs past its wall-clock limit ends as ``failed``
with the reason; its processes are ended by their own process group.
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import psutil

from companion.bus.namespace import cleanup_namespace, leftover_files
from companion.control.mission.plan import PlanError, load_plan
from companion.testing.processes import free_udp_port
from ground.campaign.scoring import TrackScore, score_track
from ground.campaign.spec import REPO, Flight

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil

from mavlink_dialect import companion as d

log = logging.getLogger(__name__)
GCS_SYSID, GCS_COMPID = 255, 190
TAIL_S = 1.0  # keep flying this long (wall) after completion: the loiter at home is in the truth
FAILSAFE_PREFIXES = ("Failsafe", "Fence breached")
DISARM_WAIT_S = 20.0  # wall: a landed vehicle's disarm heard within this after completion
CLEANUP_S = 30.0  # wall: time for the plug-ins (own sessions, ended by PDEATHSIG) to go
TIMING_INTERVAL_US = 20_000  # MISSION_CURRENT and ATTITUDE at 50 Hz (wall) to this station


class FlightError(Exception):
    """The flight could not be flown to an end (a crash, a stall, a refusal)."""


@dataclass
class Timeline:
    """What the ground station saw."""

    completed: bool = False
    start_ms: int | None = None  # vehicle (simulation) time of MISSION_START's ack
    complete_ms: int | None = None
    last_ms: int = 0
    seqs: list[int] = field(default_factory=list)
    seq_ms: list[int] = field(default_factory=list)  # vehicle time each of ``seqs`` was seen
    reached: list[int] = field(default_factory=list)  # MISSION_ITEM_REACHED, as heard
    texts: list[str] = field(default_factory=list)
    armed: bool | None = None  # as the vehicle's last heartbeat said

    def time_to_complete_s(self) -> float:
        if self.start_ms is None or self.complete_ms is None:
            return math.nan
        return (self.complete_ms - self.start_ms) / 1000.0

    def failsafes(self) -> list[str]:
        return [t for t in self.texts if t.startswith(FAILSAFE_PREFIXES)]


@dataclass(frozen=True)
class FlightJob:
    """A Ray task's argument: the flight, where to put its files, its wall-clock limit."""

    flight: Flight
    out_dir: str
    timeout_s: float
    silent_s: float = 45.0  # no MAVLink from the vehicle this long (wall): it has stalled


def fly_flight(job: FlightJob) -> dict[str, Any]:
    """Fly, score and return the flight's results row (``status`` ok or failed)."""
    flight = job.flight
    folder = Path(job.out_dir) / flight.flight_id
    folder.mkdir(parents=True, exist_ok=True)
    started = time.monotonic()
    timeline = Timeline()
    error = ""
    try:
        _fly(job, folder, timeline)
    except FlightError as exc:
        error = str(exc)
    (folder / "timeline.json").write_text(json.dumps(timeline.__dict__, indent=1))
    row = _row(flight, folder, timeline, error, time.monotonic() - started)
    row["flight_log"] = ";".join(str(p) for p in keep_flight_logs(folder))
    return row


def keep_flight_logs(folder: Path) -> list[Path]:
    """The vehicle's on-board logs of the flight moved beside its results: ``flight.ulg``
    (``flight_2.ulg``... if it armed more than once); the kept paths."""
    kept = []
    for i, path in enumerate(sorted((folder / "state" / "logs").glob("*.ulg")), 1):
        target = folder / ("flight.ulg" if i == 1 else f"flight_{i}.ulg")
        try:
            path.replace(target)
        except OSError as exc:
            log.warning("cannot keep the flight log %s: %s", path, exc)
            continue
        kept.append(target)
    return kept


def failed_row(job: FlightJob, error: str) -> dict[str, Any]:
    """The row of a flight whose task itself failed (the worker died, it was cancelled)."""
    folder = Path(job.out_dir) / job.flight.flight_id
    return _row(job.flight, folder, Timeline(), error, math.nan)


def _row(flight: Flight, folder: Path, tl: Timeline, error: str, wall_s: float) -> dict[str, Any]:
    score = TrackScore(math.nan, math.nan, math.nan, math.nan, 0)
    truth_path = folder / "truth.csv"
    if not error:
        try:
            from companion.navigation.estimate_csv import read_estimate

            score = score_track(read_estimate(truth_path), Path(flight.plan), flight.airframe,
                                flight.wind_ned)  # fmt: skip
        except (OSError, ValueError, KeyError) as exc:
            error = f"cannot score the truth: {exc}"
    sim_s = tl.last_ms / 1000.0
    return {
        "flight_id": flight.flight_id,
        "plan": Path(flight.plan).stem,
        "plan_path": flight.plan,
        "airframe": flight.airframe,
        "condition": flight.condition,
        "wind_n": flight.wind_ned[0], "wind_e": flight.wind_ned[1], "wind_d": flight.wind_ned[2],
        "turbulence": flight.turbulence,
        "gps_outages": ";".join(f"{s:g}:{d:g}" for s, d in flight.outages),
        "seed": flight.seed,
        "config": Path(flight.config).name,
        "status": "failed" if error else "ok",
        "error": error,
        "completed": tl.completed,
        **score.as_row(),
        "time_to_complete_s": tl.time_to_complete_s(),
        "sim_s": sim_s,
        "wall_s": wall_s,
        "failsafes": ";".join(tl.failsafes()),
        "armed_at_end": tl.armed,
        "log": str(folder / "sim.log"),
    }  # fmt: skip


def _fly(job: FlightJob, folder: Path, tl: Timeline) -> None:
    flight = job.flight
    port = free_udp_port()
    namespace = f"camp{os.getpid()}p{port}"
    gcs = mavutil.mavlink_connection(
        f"udpin:127.0.0.1:{port}", source_system=GCS_SYSID, source_component=GCS_COMPID
    )
    gcs.mav = d.MAVLink(gcs, srcSystem=GCS_SYSID, srcComponent=GCS_COMPID)
    with (folder / "sim.log").open("w") as sim_log:
        proc = subprocess.Popen(
            _sim_command(flight, folder, port, namespace), cwd=REPO, stdout=sim_log,
            stderr=subprocess.STDOUT, start_new_session=True,
        )  # fmt: skip
        try:
            pilot = _Pilot(gcs, proc, time.monotonic() + job.timeout_s, tl, job.silent_s)
            pilot.endless_seq = endless_final_item(flight.plan)
            pilot.fly(flight.start_at_s, plan_lands(flight.plan))
        finally:
            _end(proc)
            gcs.close()
            _end_stragglers(namespace)
            _clean(namespace)


def _sim_command(flight: Flight, folder: Path, port: int, namespace: str) -> list[str]:
    cmd = [
        sys.executable, "-m", "companion", "sim", "--speed", "max",
        "--config", flight.config, "--aircraft", flight.airframe, "--plan", flight.plan,
        "--wind", ",".join(f"{v:g}" for v in flight.wind_ned),
        "--turbulence", flight.turbulence, "--seed", str(flight.seed),
        "--duration", f"{flight.max_sim_s:g}", "--truth", str(folder / "truth.csv"),
        "--state-dir", str(folder / "state"), "--link", f"udpout://127.0.0.1:{port}",
        "--namespace", namespace, "--log-level", "WARNING",
    ]  # fmt: skip
    for start, seconds in flight.outages:
        cmd += ["--gps-outage", f"{start:g}:{seconds:g}"]
    if flight.airborne:
        cmd.append("--airborne")
    if flight.noise != 1.0:
        cmd += ["--noise", f"{flight.noise:g}"]
    if flight.gps_wander_m is not None:
        cmd += ["--gps-wander", f"{flight.gps_wander_m:g}"]
    if flight.gps_receiver != "standard":
        cmd += ["--gps-receiver", flight.gps_receiver]
    if flight.start_at_s is not None:
        cmd += ["--start-at", f"{flight.start_at_s:g}", "--fast" if flight.fast else "--exact"]
    return cmd


def endless_final_item(plan: str | Path) -> int | None:
    """The seq of the plan's last mission item when it is an unlimited loiter."""
    items = load_plan(plan).get(0, [])
    if items and items[-1].command == d.MAV_CMD_NAV_LOITER_UNLIM:
        return items[-1].seq
    return None


def plan_lands(plan: str) -> bool:
    """Whether the plan ends in a landing (then the flight ends disarmed)."""
    try:
        return any(it.command == d.MAV_CMD_NAV_LAND for it in load_plan(plan).get(0, []))
    except PlanError:
        return False


def _armed(msg: Any) -> bool:
    return (
        msg.get_type() == "HEARTBEAT"
        and msg.get_srcSystem() == 1
        and bool(msg.base_mode & d.MAV_MODE_FLAG_SAFETY_ARMED)
    )


class _Pilot:
    """The ground station's side: heartbeats, arm, start, follow the mission."""

    def __init__(
        self, gcs: Any, proc: subprocess.Popen, deadline: float, tl: Timeline, silent_s: float
    ) -> None:
        self.gcs, self.proc, self.deadline, self.tl = gcs, proc, deadline, tl
        self.silent_s = silent_s
        self.endless_seq: int | None = None  # a final item that never ends (see _complete)
        self.heard = time.monotonic()
        self.next_beat = 0.0

    def fly(self, start_at_s: float | None, lands: bool = False) -> None:
        """Arm and start (or, when the simulator starts the mission, see it armed)."""
        self._until(lambda m: m.get_type() == "HOME_POSITION", "the vehicle's home position")
        # The completion time is read off the telemetry: the faster it comes, the finer.
        for msg_id in (d.MAVLINK_MSG_ID_MISSION_CURRENT, d.MAVLINK_MSG_ID_ATTITUDE):
            self.gcs.mav.command_long_send(
                1, 1, d.MAV_CMD_SET_MESSAGE_INTERVAL, 0, msg_id, TIMING_INTERVAL_US, 0, 0, 0, 0, 0
            )
        if start_at_s is None:
            self._command(d.MAV_CMD_COMPONENT_ARM_DISARM, 1.0)
            self._command(d.MAV_CMD_MISSION_START, 0.0)
            self.tl.start_ms = self.tl.last_ms
        else:
            self._until(_armed, "arming by the simulator")
            self.tl.start_ms = round(start_at_s * 1000)
        self._until(self._complete, "mission completion")
        if lands:  # a landing ends with the vehicle disarming itself: wait to hear it
            self._until(lambda m: self.tl.armed is False, "disarming", DISARM_WAIT_S, False)
        tail_end = time.monotonic() + TAIL_S
        while time.monotonic() < tail_end:
            self._next()

    def _complete(self, msg: Any) -> bool:
        if msg.get_type() != "MISSION_CURRENT":
            return False
        if not self.tl.seqs or self.tl.seqs[-1] != msg.seq:
            self.tl.seqs.append(msg.seq)
            self.tl.seq_ms.append(self.tl.last_ms)
        # A plan that ends in an unlimited loiter is never COMPLETE: it is done once that
        # loiter is the current item, with nothing left to fly.
        if msg.mission_state == d.MISSION_STATE_COMPLETE or msg.seq == self.endless_seq:
            self.tl.completed, self.tl.complete_ms = True, self.tl.last_ms
            return True
        return False

    def _command(self, command: int, p1: float) -> None:
        for attempt in range(3):
            self.gcs.mav.command_long_send(1, 1, command, attempt, p1, 0, 0, 0, 0, 0, 0)
            ack = self._until(
                lambda m: m.get_type() == "COMMAND_ACK" and m.command == command,
                f"command {command}'s ack", within_s=3.0, required=False,
            )  # fmt: skip
            if ack is not None:
                if ack.result != d.MAV_RESULT_ACCEPTED:
                    name = d.enums["MAV_RESULT"][ack.result].name
                    raise FlightError(f"command {command} refused: {name}")
                return
        raise FlightError(f"command {command}: no answer")

    def _until(self, want, what: str, within_s: float | None = None, required: bool = True):
        end = self.deadline if within_s is None else min(self.deadline, time.monotonic() + within_s)
        while time.monotonic() < end:
            msg = self._next()
            if msg is not None and want(msg):
                return msg
        if required or time.monotonic() >= self.deadline:
            raise FlightError(f"hung: no {what} within the flight's time limit")
        return None

    def _next(self) -> Any:
        now = time.monotonic()
        if now >= self.next_beat:  # a ground station's heartbeat, as QGroundControl sends
            self.gcs.mav.heartbeat_send(d.MAV_TYPE_GCS, d.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            self.next_beat = now + 1.0
        msg = self.gcs.recv_match(blocking=True, timeout=0.2)
        if msg is None:
            self._check_alive(now)
            return None
        self.heard = now
        self._note(msg)
        return msg

    def _check_alive(self, now: float) -> None:
        if self.proc.poll() is not None:
            raise FlightError(f"the simulation ended (exit {self.proc.returncode}) before the end")
        if now - self.heard > self.silent_s:
            raise FlightError(f"hung: the vehicle was silent for {self.silent_s:.0f} s")

    def _note(self, msg: Any) -> None:
        ms = getattr(msg, "time_boot_ms", None)
        if ms is not None and msg.get_srcSystem() == 1:
            self.tl.last_ms = max(self.tl.last_ms, int(ms))
        if msg.get_type() == "STATUSTEXT":
            self.tl.texts.append(msg.text)
        elif msg.get_type() == "MISSION_ITEM_REACHED" and msg.get_srcSystem() == 1:
            self.tl.reached.append(msg.seq)
        elif msg.get_type() == "HEARTBEAT" and msg.get_srcSystem() == 1:
            self.tl.armed = bool(msg.base_mode & d.MAV_MODE_FLAG_SAFETY_ARMED)


def _end(proc: subprocess.Popen) -> None:
    """SIGTERM the flight's process group, then SIGKILL what is left of it."""
    if proc.poll() is None:
        _signal_group(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            log.warning("flight pid %d did not stop: killing its group", proc.pid)
    _signal_group(proc.pid, signal.SIGKILL)  # the group outlives a clean leader sometimes
    proc.wait()


def _end_stragglers(namespace: str) -> None:
    """SIGKILL what is left of the flight outside its process group (its plug-ins run in
    sessions of their own and end with their parent, seconds later on a busy machine, and
    one still retrying its device may open bus files after the namespace was cleaned), and
    wait until it is gone. The flight's processes carry its namespace on their command
    line (forked plug-ins keep ``companion sim``'s)."""
    token = f"--namespace {namespace} "
    deadline = time.monotonic() + CLEANUP_S
    while time.monotonic() < deadline:
        left = [
            p
            for p in psutil.process_iter(["cmdline"])
            if token in " ".join(p.info["cmdline"] or []) + " "
        ]
        if not left:
            return
        for proc in left:
            with contextlib.suppress(psutil.Error):
                proc.kill()
        psutil.wait_procs(left, timeout=1.0)
    log.warning("flight namespace %s: processes left", namespace)


def _clean(namespace: str) -> None:
    """Remove what a killed vehicle left in /dev/shm. Its plug-ins run in sessions of their
    own, out of reach of the group's signals: they end when their parent does, and one
    still shutting down (seconds, on a busy machine) is a living node to iceoryx2, while
    which nothing is removed. So again, until nothing is left or the time is up."""
    deadline = time.monotonic() + CLEANUP_S
    while True:
        # Until nothing is left: a pass that removed some files (a dead node's) may leave
        # those of a node still alive then, whose process is still ending.
        cleanup_namespace(namespace)
        if not leftover_files(namespace):
            return
        if time.monotonic() > deadline:
            log.warning("flight namespace %s: files left in /dev/shm", namespace)
            return
        time.sleep(0.1)


def _signal_group(pgid: int, sig: int) -> None:
    try:
        os.killpg(pgid, sig)
    except (ProcessLookupError, PermissionError):
        pass
