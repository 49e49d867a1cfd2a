"""Two vehicles on one machine, each with its own mission: each flies its own.

Both run ``companion sim`` with the config's default state directory (HOME points into
the test's own directory), so only the namespace keeps their missions and parameters
apart; a ground station uploads a different plan to each, arms both and starts both.
"""

from __future__ import annotations

import math
import os
import sys
import time

import pytest

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil

from companion.control.mission.plan import load_plan
from companion.exec_control.config import STATE_ENV
from mavlink_dialect import companion as d
from tests.protocol.mav_client import free_udp_port
from tests.sim.sim_run import SimRun, finish
from tests.support.vehicle import REPO, companion_env, unique_namespace

PLANS = {
    "square": REPO / "qgc_plans" / "square.plan",
    "short": REPO / "qgc_plans" / "short_leg.plan",
}


def _start(tmp_path, name: str, port: int):
    namespace = unique_namespace(f"two{name}")
    env = companion_env(namespace)
    env["HOME"] = str(tmp_path)  # the default state directory lands here
    env.pop(STATE_ENV, None)  # the session's own default (tests/conftest.py) left out
    cmd = [
        sys.executable, "-m", "companion", "sim", "--speed", "max", "--namespace", namespace,
        "--link", f"udpout://127.0.0.1:{port}", "--duration", "1500",
    ]  # fmt: skip
    return SimRun(cmd, tmp_path / f"{name}_output.log", env), namespace


def _upload(conn, items) -> None:
    conn.mav.mission_count_send(1, 1, len(items), 0)
    for _ in items:
        req = conn.recv_match(
            type=["MISSION_REQUEST_INT", "MISSION_REQUEST"], blocking=True, timeout=20
        )
        assert req is not None, "no mission request"
        it = items[req.seq]
        conn.mav.mission_item_int_send(
            1, 1, it.seq, it.frame, it.command, 0, it.autocontinue,
            it.param1, it.param2, it.param3, it.param4, it.x, it.y, it.z, 0,
        )  # fmt: skip
    ack = conn.recv_match(type="MISSION_ACK", blocking=True, timeout=20)
    assert ack is not None and ack.type == d.MAV_MISSION_ACCEPTED


def _arm_and_start(conn) -> None:
    for command, params in (
        (d.MAV_CMD_COMPONENT_ARM_DISARM, (1,)),
        (d.MAV_CMD_MISSION_START, (0, 0)),
    ):
        for _ in range(20):
            conn.mav.command_long_send(1, 1, command, 0, *params, *[0] * (7 - len(params)))
            ack = conn.recv_match(type="COMMAND_ACK", blocking=True, timeout=3)
            if ack is not None and ack.command == command and ack.result == d.MAV_RESULT_ACCEPTED:
                break
        else:
            raise AssertionError(f"command {command} not accepted")


def _positions_at_reached(conns: dict, seq: int) -> dict[str, tuple[float, float]]:
    """Where each vehicle was (its last GLOBAL_POSITION_INT) when it reached item ``seq``."""
    where = {name: (math.nan, math.nan) for name in conns}
    found: dict[str, tuple[float, float]] = {}
    deadline = time.monotonic() + 300
    while len(found) < len(conns):
        assert time.monotonic() < deadline, f"item {seq} not reached by {set(conns) - set(found)}"
        idle = True
        for name, conn in conns.items():
            msg = conn.recv_match(type=["MISSION_ITEM_REACHED", "GLOBAL_POSITION_INT"])
            if msg is None:
                continue
            idle = False
            if msg.get_type() == "GLOBAL_POSITION_INT":
                where[name] = (msg.lat / 1e7, msg.lon / 1e7)
            elif msg.seq == seq and name not in found:
                found[name] = where[name]
        if idle:
            time.sleep(0.005)
    return found


def _metres(a: tuple[float, float], b: tuple[float, float]) -> float:
    dn = (a[0] - b[0]) * 111_320
    de = (a[1] - b[1]) * 111_320 * math.cos(math.radians(a[0]))
    return math.hypot(dn, de)


@pytest.mark.timeout(420)
def test_two_vehicles_each_fly_their_own_mission(tmp_path):
    plans = {name: load_plan(path)[0] for name, path in PLANS.items()}
    ports = {name: free_udp_port() for name in plans}
    conns = {
        n: mavutil.mavlink_connection(f"udpin:127.0.0.1:{p}", source_system=255)
        for n, p in ports.items()
    }
    runs = {name: _start(tmp_path, name, port) for name, port in ports.items()}
    try:
        for name, conn in conns.items():
            assert conn.recv_match(type="HOME_POSITION", blocking=True, timeout=120), name
            _upload(conn, plans[name])
        for conn in conns.values():
            _arm_and_start(conn)
        reached = _positions_at_reached(conns, 2)
        for name, where in reached.items():
            target = plans[name][2]
            other = plans["short" if name == "square" else "square"][2]
            own, theirs = (target.x / 1e7, target.y / 1e7), (other.x / 1e7, other.y / 1e7)
            assert _metres(where, own) < _metres(where, theirs), (name, where, own, theirs)
    finally:
        for proc, namespace in runs.values():
            proc.terminate()
            finish(proc, namespace, 60)
        for conn in conns.values():
            conn.close()
    dirs = sorted(p.name for p in (tmp_path / ".local/state/companion/sim").iterdir())
    assert dirs == sorted(ns for _, ns in runs.values())
