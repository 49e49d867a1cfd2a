"""What benchmarks/cpu_quota.py sees of a flying vehicle from outside its quota.

A thread on the vehicle's bus and on a UDP endpoint of its link (a second ground station):
IMU first byte -> Mini SSC frame written (the servo plug-in's ``command_t_us`` against this
process's clock, both monotonic: the vehicle flies on the hardware time base), the
navigator's state rate, ATTITUDE and GLOBAL_POSITION_INT as they arrive, the vehicle's
warnings, and its health table (the plug-ins' dropped and bad counters and restarts).
The MAVSDK flight (``fly_watched``) marks when the aircraft was armed and when the mission
ended; rates and latencies count that stretch only.
"""

from __future__ import annotations

import asyncio
import os
import socket
import threading
import time

import numpy as np
from mavsdk.plugins.action import ActionError

from companion.bus.node import BusNode
from companion.messages.channels import KEEP
from mavlink_dialect import companion as m
from tests.support.mavsdk_flight import mission_finished, plan_uploaded, until

ARM_TRIES_S = 120.0  # pre-arm checks may take longer on a slow board: keep asking
ROLLOUT_S = 90.0  # a landing's mission ends at touchdown: the roll-out and disarming follow


class Watch:
    """The watcher thread; ``port`` is the UDP port the vehicle's link must send to."""

    def __init__(self, renice: dict[str, int] | None = None) -> None:
        self.renice, self.reniced = renice or {}, set()
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.setblocking(False)
        self.port = self.sock.getsockname()[1]
        self.t0 = time.monotonic()
        self.armed_at = self.ended_at = float("nan")
        self.servo: list[tuple[float, int]] = []  # (arrival s, latency µs)
        self.arrivals: dict[str, list[float]] = {"nav": [], "control": [], "ATTITUDE": [],
                                                 "GLOBAL_POSITION_INT": []}  # fmt: skip
        self.events: list[tuple[float, str]] = []
        self.imu_at_arming = 0
        self.health: dict[str, dict] = {}
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def event(self, what: str) -> None:
        """Something that went wrong, stamped in seconds since the watch began."""
        self.events.append((time.monotonic() - self.t0, what))

    def start_on(self, namespace: str) -> None:
        self._thread = threading.Thread(target=self._run, args=(namespace,), daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread:
            self._thread.join(timeout=10)
        self.sock.close()

    def _run(self, namespace: str) -> None:
        parser = m.MAVLink(None)
        with BusNode(namespace, "quota_watch") as bus:
            # Every value since the last wake-up, not the newest only: the rates count them.
            nav = bus.latest_reader("nav/state", keep=KEEP)
            servos = bus.latest_reader("actuators/servos", keep=KEEP)
            control = bus.queue_reader("control/actuators")
            health = bus.latest_reader("system/health")
            waiter = bus.waiter([nav, servos, control])
            next_health = 0.0
            while not self._stop.is_set():
                waiter.wait(0.005)
                now = time.monotonic()
                now_us = time.monotonic_ns() // 1000
                for _ in nav.drain():
                    self.arrivals["nav"].append(now)
                for _ in control.drain():
                    self.arrivals["control"].append(now)
                for msg in servos.drain():
                    if msg.command_t_us > 0:
                        self.servo.append((now, now_us - msg.command_t_us))
                self._udp(parser, now)
                if now >= next_health:
                    next_health = now + 1.0
                    table = health.get()
                    if table is not None:
                        self._note_health(table)

    def _udp(self, parser: m.MAVLink, now: float) -> None:
        while True:
            try:
                data = self.sock.recv(65536)
            except (BlockingIOError, OSError):
                return
            for msg in parser.parse_buffer(data) or []:
                kind = msg.get_type()
                if kind in self.arrivals:
                    self.arrivals[kind].append(now)
                elif kind == "STATUSTEXT" and msg.severity <= m.MAV_SEVERITY_WARNING:
                    self.event(f"vehicle: {msg.text}")

    def _note_health(self, table: object) -> None:
        for row in table.rows():
            item = row.as_dict()
            name = item["name"]
            if name in self.renice and item["pid"] and item["pid"] not in self.reniced:
                os.setpriority(os.PRIO_PROCESS, item["pid"], self.renice[name])
                self.reniced.add(item["pid"])
            before = self.health.get(name)
            if before and item["restarts"] > before["restarts"]:
                self.event(f"{name} restarted")
            self.health[name] = item

    def summary(self, seen: dict) -> dict:
        """The row's figures from the armed-to-ended stretch."""
        start, end = self.armed_at, self.ended_at
        if np.isnan(end):
            end = time.monotonic()
        span = max(end - start, 1e-9) if not np.isnan(start) else float("nan")
        row: dict = {}
        for key, name in (("nav_hz", "nav"), ("ctl_hz", "control"), ("att_hz", "ATTITUDE"),
                          ("gpi_hz", "GLOBAL_POSITION_INT")):  # fmt: skip
            row[key] = sum(start <= t <= end for t in self.arrivals[name]) / span
        lat = [us / 1000 for t, us in self.servo if start <= t <= end]
        if lat:
            row["servo_p50_ms"], row["servo_p99_ms"] = (float(v) for v in
                                                        np.percentile(lat, [50, 99]))  # fmt: skip
            row["servo_over_20ms"] = sum(v > 20 for v in lat)
        rows = self.health.values()
        imu = self.health.get("imu", {}).get("frames_ok", 0)
        row["imu_hz"] = (imu - self.imu_at_arming) / span
        row["dropped"] = sum(int(r["dropped"]) for r in rows)
        row["bad"] = sum(int(r["frames_bad"]) for r in rows)
        row["restarts"] = sum(int(r["restarts"]) for r in rows)
        failures = sorted(self.events)
        row["first_failure"] = f"{failures[0][1]} (t {failures[0][0]:.0f} s)" if failures else ""
        kept = ("dropped", "frames_bad", "restarts", "cpu_pct", "step_p50_us")
        row["health"] = {k: {f: v[f] for f in kept} for k, v in self.health.items()}
        return row


async def fly_watched(
    port: int, plan: str, deadline_s: float, watch: Watch, lands: bool = False
) -> dict:
    """Upload ``plan``, arm (asking again while refused), start, wait for its end (and, for
    a plan that ``lands``, for the vehicle to disarm itself once it has stopped)."""
    seen: dict = {}
    async with plan_uploaded(port, plan, connect_s=120.0) as flight:
        give_up = time.monotonic() + ARM_TRIES_S
        while True:
            try:
                await flight.action.arm()
                break
            except ActionError as exc:
                if "arm_refused" not in seen:
                    watch.event(f"arm refused: {exc.result.name}")
                seen["arm_refused"] = exc.result.name
                if time.monotonic() > give_up:
                    raise
                await asyncio.sleep(2.0)
        watch.armed_at = time.monotonic()
        watch.imu_at_arming = watch.health.get("imu", {}).get("frames_ok", 0)
        await flight.mission.start_mission()
        seen["finished"] = await mission_finished(flight.mission, deadline_s)
        watch.ended_at = time.monotonic()
        if not seen["finished"]:
            watch.event(f"mission not finished in {deadline_s:.0f} s")
        elif lands:
            try:
                armed = flight.telemetry.subscribe_armed()
                await until(armed, lambda a: not a, "disarmed", ROLLOUT_S)
                seen["disarmed"] = True
            except AssertionError as exc:
                watch.event(str(exc))
    return seen
