"""Lockstep simulation speed with the whole vehicle running.

Usage: uv run python benchmarks/sitl_speed.py [--aircraft c172p] [--seconds 300] [--config TOML]

Runs ``companion sim --speed max --airborne`` for the given simulated time, arms it and
makes it loiter (so the controller and the servo card are in the loop, in lockstep with
the simulator), and prints the speed factor (simulated seconds per wall second, target
≥ 20×) from the bridge's own count, the CPU each process used, and the speed of JSBSim
alone for comparison. ``--disarmed`` leaves the flight plug-ins stopped.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil

from ground.campaign.flight_run import free_udp_port
from mavlink_dialect import companion as d

REPO = Path(__file__).resolve().parents[1]
RESULT = re.compile(
    r"simulated ([\d.]+) s in ([\d.]+) s wall \(([\d.]+)x\); lockstep stalls (\d+); "
    r"control stalls (.*)"
)


def jsbsim_alone(aircraft: str, seconds: float) -> float:
    """Speed factor of the flight dynamics with nothing else (the ceiling)."""
    from bridges.jsbsim.fdm import Flight, Home
    from companion.actuators.airframe import load_airframe

    frame = load_airframe(aircraft)
    saved = os.dup(1)  # JSBSim prints a banner on stdout
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
    try:
        flight = Flight(frame.jsbsim_model, 100.0, Home(), 300.0, frame.cruise_speed_m_s)
    finally:
        os.dup2(saved, 1)
    started = time.perf_counter()
    while flight.t_s < seconds:
        flight.step()
        flight.state()
    return seconds / (time.perf_counter() - started)


def process_name(cmdline: list[str]) -> str:
    """The plug-in's instance name for a plug-in host, else the module it runs."""
    if "companion.exec_control.plugin_host" in cmdline:
        return f"plug-in {json.loads(cmdline[-1])['name']}"
    module = cmdline[cmdline.index("-m") + 1] if "-m" in cmdline else " ".join(cmdline[:3])
    return module


def cpu_of_tree(proc: psutil.Process, seen: dict[int, tuple[str, float]]) -> None:
    """Remember each process's name and CPU seconds so far (they vanish at the end)."""
    for p in [proc, *proc.children(recursive=True)]:
        try:
            t = p.cpu_times()
            name = process_name(p.cmdline())
            seen[p.pid] = (name, t.user + t.system)
        except psutil.Error:
            pass


def arm_and_loiter(station: mavutil.mavfile) -> None:
    """Start the flight plug-ins and circle where it is (the controller flies)."""
    for command, params in (
        (d.MAV_CMD_COMPONENT_ARM_DISARM, (1,)),
        (d.MAV_CMD_NAV_LOITER_UNLIM, ()),
    ):
        station.mav.command_long_send(1, 1, command, 0, *[*params, 0, 0, 0, 0, 0, 0, 0][:7])
        ack = station.recv_match(type="COMMAND_ACK", blocking=True, timeout=10)
        if ack is None or ack.result != d.MAV_RESULT_ACCEPTED:
            sys.stderr.write(f"command {command} not accepted: {ack}\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--aircraft", default="c172p")
    parser.add_argument("--seconds", type=float, default=300.0)
    parser.add_argument("--disarmed", action="store_true", help="do not arm")
    parser.add_argument("--exact", action="store_true", help="lockstep with the control loop")
    parser.add_argument("--config", type=Path, help="vehicle config (default: the shipped sim)")
    args = parser.parse_args()
    port = free_udp_port()
    station = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=255)
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, COMPANION_BUS=f"sitlbench{os.getpid()}")
        cmd = [
            sys.executable, "-m", "companion", "sim", "--speed", "max", "--airborne",
            "--aircraft", args.aircraft, "--duration", str(args.seconds),
            "--state-dir", tmp, "--link", f"udpout://127.0.0.1:{port}",
            "--exact" if args.exact else "--fast",
        ]  # fmt: skip
        if args.config is not None:
            cmd += ["--config", str(args.config)]
        proc = subprocess.Popen(cmd, cwd=REPO, env=env, text=True, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT)  # fmt: skip
        root, cpu = psutil.Process(proc.pid), {}
        armed = args.disarmed
        while proc.poll() is None:
            cpu_of_tree(root, cpu)
            if not armed and station.recv_match(type="HOME_POSITION", blocking=True, timeout=0.2):
                arm_and_loiter(station)
                armed = True
            time.sleep(0.2)
        out = proc.stdout.read() if proc.stdout else ""
    station.close()
    match = RESULT.search(out)
    if proc.returncode != 0 or match is None:
        sys.stderr.write(out)
        raise SystemExit("the simulation did not finish")
    sim_s, wall_s, factor, stalls, control = match.groups()
    state = "disarmed" if args.disarmed else "armed, loitering"
    state += ", exact lockstep" if args.exact else ", fast lockstep"
    print(f"aircraft {args.aircraft} ({state}): {sim_s} s simulated in {wall_s} s wall")
    print(f"lockstep speed factor, whole vehicle: {factor}x   (target >= 20x; stalls {stalls})")
    print(f"lockstep with the control loop: stalls {control}")
    print(f"JSBSim alone: {jsbsim_alone(args.aircraft, 60.0):.0f}x")
    print("CPU seconds per process over the run (start-up imports included):")
    for name, seconds in sorted(cpu.values(), key=lambda v: -v[1]):
        if name:
            print(f"  {seconds:6.2f}  {name}")


if __name__ == "__main__":
    main()
