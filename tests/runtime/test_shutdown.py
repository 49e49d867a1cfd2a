"""SIGINT/SIGTERM stop everything within 2 s, leaving no process and no shared memory."""

from __future__ import annotations

import os
import signal

import psutil
import pytest

from tests.support.configs import pipeline
from tests.support.vehicle import assert_clean, wait_for


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_signal_stops_everything_quickly_and_cleanly(vehicle_factory, sig):
    vehicle = vehicle_factory(pipeline())
    for name in ("imu", "relay", "idle"):
        vehicle.wait_running(name)
    pids = vehicle.all_pids()
    plugins = {vehicle.row(name).pid for name in ("imu", "relay", "idle")}
    assert plugins <= set(pids)
    assert len(pids) == 5  # the supervisor, its fork server and the three plug-ins
    vehicle.bus.close()  # the test's own node must not hold the namespace open
    vehicle.bus = None

    took = vehicle.stop(sig)

    assert took < 2.0, f"shutdown took {took:.2f} s"
    assert vehicle.proc.returncode == 0
    alive = [p for p in pids if psutil.pid_exists(p) and psutil.Process(p).status() != "zombie"]
    assert not alive, f"orphans left: {alive}"
    assert_clean(vehicle.namespace)


def test_supervisor_killed_with_sigkill_takes_its_plugins_along(vehicle_factory):
    vehicle = vehicle_factory(pipeline())
    for name in ("imu", "relay", "idle"):
        vehicle.wait_running(name)
    children = vehicle.all_pids()[1:]
    os.kill(vehicle.proc.pid, signal.SIGKILL)
    vehicle.proc.wait(timeout=5)

    def gone() -> bool:
        return not any(psutil.pid_exists(p) for p in children)

    wait_for(gone, 3, "plug-ins to exit after their supervisor was killed")

    # What the killed vehicle left in shared memory must not break the next start.
    again = vehicle_factory(pipeline(), namespace=vehicle.namespace)
    nav = again.bus.latest_reader("nav/state")
    again.wait_running("relay")
    assert wait_for(lambda: nav.wait(0.2), 10, "data flowing on the restarted vehicle")
