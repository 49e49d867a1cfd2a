"""Link figures: a saturated 57600-baud radio on a real pty, and bulk transfers over UDP.

Usage: uv run python benchmarks/link_budget.py [--seconds 20]

1. The vehicle's link endpoint is a pseudo-terminal at 57600 baud; this script reads the
   other end no faster than 57600 baud would deliver (5760 bytes/s), asks for telemetry
   far beyond what fits, and sends a command every 0.5 s: it prints command-ACK latency
   (target ≤ 300 ms), the telemetry rates achieved, and the most bytes ever waiting in
   the pty (bounded: the link never queues).
2. Over loopback UDP with MAVSDK: time to download all parameters (target ≤ 0.5 s) and
   to upload a 500-item mission (target ≤ 2 s).
"""

from __future__ import annotations

import argparse
import asyncio
import fcntl
import os
import select
import signal
import subprocess
import sys
import tempfile
import termios
import time
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

os.environ.setdefault("MAVLINK20", "1")
from mavlink_dialect import companion as m

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
from tests.support.configs import TICKER, client_vehicle, plugin  # noqa: E402


def vehicle(endpoint: str, state: Path) -> str:
    """A known navigation solution, a 200 Hz IMU, the commander and the real controller
    (whose parameters the ground station downloads)."""
    return client_vehicle(
        endpoint,
        state,
        extra=(plugin("imu", TICKER, rate_hz=200.0),),
        flight=plugin("control", "control.fixed_wing", "flight"),
        name="linkbench",
        airframe="c172p",
    )


def wait_for_heartbeat(master: int, parser: Any, timeout_s: float = 60.0) -> None:
    """Read the pty until the vehicle's first HEARTBEAT (the link plug-in is running)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        ready, _, _ = select.select([master], [], [], 0.2)
        if ready:
            msgs = parser.parse_buffer(os.read(master, 4096)) or []
            if any(msg.get_type() == "HEARTBEAT" for msg in msgs):
                return
    raise SystemExit("the vehicle's link did not start on the pty")


def start_vehicle(endpoint: str, tmp: Path, namespace: str) -> subprocess.Popen[bytes]:
    config = tmp / f"{namespace}.toml"
    config.write_text(vehicle(endpoint, tmp / namespace))
    env = {**os.environ, "COMPANION_BUS": namespace, "PYTHONPATH": str(REPO)}
    return subprocess.Popen(
        [sys.executable, "-m", "companion", "run", "-c", str(config), "--log-level", "WARNING"],
        env=env,
        cwd=REPO,
    )


def stop(proc: subprocess.Popen[bytes]) -> None:
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=10)


def saturated_radio(seconds: float, tmp: Path) -> None:
    master, slave = os.openpty()
    attrs = termios.tcgetattr(slave)
    attrs[3] &= ~(termios.ECHO | termios.ICANON)
    termios.tcsetattr(slave, termios.TCSANOW, attrs)
    vehicle = start_vehicle(f"serial://{os.ttyname(slave)}:57600", tmp, f"lb{os.getpid()}a")
    gcs = m.MAVLink(None, srcSystem=255, srcComponent=190)
    parser = m.MAVLink(None)
    parser.robust_parsing = True
    bytes_per_s = 57600 / 10
    try:
        wait_for_heartbeat(master, parser)  # the link is up: it hears what is sent now
        for msg_id in (
            m.MAVLINK_MSG_ID_ATTITUDE,
            m.MAVLINK_MSG_ID_GLOBAL_POSITION_INT,
            m.MAVLINK_MSG_ID_SCALED_IMU,
            m.MAVLINK_MSG_ID_VFR_HUD,
        ):
            cmd = gcs.command_long_encode(
                1, 1, m.MAV_CMD_SET_MESSAGE_INTERVAL, 0, msg_id, 5000, 0, 0, 0, 0, 0
            )  # 200 Hz each: far too much
            os.write(master, cmd.pack(gcs))
        counts: Counter[str] = Counter()
        latencies, queued = [], []
        pending: float | None = None
        t0 = time.monotonic()
        next_cmd = t0 + 1.0
        credit = 0.0
        last = t0
        while (now := time.monotonic()) - t0 < seconds:
            credit = min(credit + (now - last) * bytes_per_s, 512)
            last = now
            waiting = np.frombuffer(fcntl.ioctl(master, termios.FIONREAD, b"\0" * 4), np.int32)[0]
            queued.append(int(waiting))
            take = int(min(credit, waiting))
            if take > 0:
                credit -= take
                for msg in parser.parse_buffer(os.read(master, take)) or []:
                    counts[msg.get_type()] += 1
                    is_ack = msg.get_type() == "COMMAND_ACK"
                    if is_ack and msg.command == m.MAV_CMD_REQUEST_MESSAGE and pending is not None:
                        latencies.append(now - pending)
                        pending = None
            if now >= next_cmd and pending is None:
                cmd = gcs.command_long_encode(
                    1,
                    1,
                    m.MAV_CMD_REQUEST_MESSAGE,
                    0,
                    m.MAVLINK_MSG_ID_SYS_STATUS,
                    0,
                    0,
                    0,
                    0,
                    0,
                    0,
                )
                os.write(master, cmd.pack(gcs))
                pending, next_cmd = now, now + 0.5
            time.sleep(0.002)  # the bench reader's own pacing, like a radio's serial port
        elapsed = time.monotonic() - t0
    finally:
        stop(vehicle)
        os.close(master)
        os.close(slave)
    lat = np.array(latencies) * 1000
    print(f"57600-baud pty, reader throttled to {bytes_per_s:.0f} B/s, {elapsed:.0f} s:")
    print(
        f"  command-ACK latency under saturation: p50 {np.percentile(lat, 50):.0f} ms, "
        f"max {lat.max():.0f} ms over {len(lat)} commands (target ≤ 300 ms)"
    )
    for name in (
        "HEARTBEAT",
        "ATTITUDE",
        "GLOBAL_POSITION_INT",
        "SCALED_IMU",
        "VFR_HUD",
        "SYS_STATUS",
    ):
        print(f"  {name:20} {counts[name] / elapsed:6.1f} Hz")
    print(f"  bytes waiting in the pty: max {max(queued)}, mean {np.mean(queued):.0f} (bounded)")


async def bulk_transfers(tmp: Path) -> None:
    from mavsdk.asyncio import Configuration, Mavsdk
    from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync
    from mavsdk.asyncio.plugins.param import ParamAsync
    from mavsdk.component_type import ComponentType
    from mavsdk.plugins.mission_raw import MissionItem

    port = 24000 + os.getpid() % 1000
    vehicle = start_vehicle(f"udpout://127.0.0.1:{port}", tmp, f"lb{os.getpid()}b")
    try:
        config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
        async with Mavsdk(config) as mavsdk:
            await mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
            system = await mavsdk.first_autopilot(timeout_s=20.0)
            t0 = time.perf_counter()
            params = await ParamAsync(system).get_all_params()
            t_params = time.perf_counter() - t0
            items = [
                MissionItem(
                    i,
                    6,
                    16,
                    int(i == 0),
                    1,
                    0.0,
                    10.0,
                    0.0,
                    0.0,
                    -379105000 + i * 100,
                    1451340000 + i * 100,
                    100.0,
                    0,
                )
                for i in range(500)
            ]
            t0 = time.perf_counter()
            await MissionRawAsync(system).upload_mission(items)
            t_mission = time.perf_counter() - t0
    finally:
        stop(vehicle)
    count = len(params.float_params) + len(params.int_params)
    print("loopback UDP with MAVSDK:")
    print(f"  download all {count} parameters: {t_params * 1000:.0f} ms (target ≤ 500 ms)")
    print(f"  upload a 500-item mission: {t_mission * 1000:.0f} ms (target ≤ 2000 ms)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        saturated_radio(args.seconds, Path(tmp))
        asyncio.run(bulk_transfers(Path(tmp)))


if __name__ == "__main__":
    main()
