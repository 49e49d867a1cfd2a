"""A second vehicle started on a bus namespace where one already runs is refused, and the
running one is left alone: two would read each other's sensors and commands (a
technician's `companion run` beside the service on the aircraft), and a second simulator
would drive the first vehicle's clock."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

from companion.bus.namespace import running_supervisor
from companion.exec_control.supervisor import EXIT_BUS_IN_USE
from tests.support.configs import TICKER, plugin, vehicle_config
from tests.support.vehicle import REPO, wait_for


@pytest.mark.timeout(90)
def test_a_second_vehicle_on_a_busy_namespace_is_refused_and_the_first_flies_on(
    vehicle_factory,
):
    config = vehicle_config("first", plugin("tick", TICKER))
    first = vehicle_factory(config)
    first.wait_running("tick")
    supervisor = running_supervisor(first.namespace)
    assert supervisor is not None
    second = vehicle_factory(config, namespace=first.namespace)
    assert second.proc is not None
    assert second.proc.wait(timeout=60) == EXIT_BUS_IN_USE
    said = second.output()
    assert f"is in use by the vehicle of process {supervisor}" in said, said
    # The first vehicle's plug-in still runs in the same process, and its health table is
    # still published: the refused start touched nothing of it.
    pid = first.row("tick").pid
    seen = first.health().t_us
    wait_for(lambda: first.health().t_us > seen, 5, "a newer health table")
    row = first.row("tick")
    assert row.pid == pid and row.restarts == 0
    assert first.proc is not None and first.proc.poll() is None
    time.sleep(0.1)
    assert running_supervisor(first.namespace) == supervisor


@pytest.mark.timeout(120)
def test_companion_sim_on_a_busy_namespace_is_refused_before_its_simulator_starts(
    vehicle_factory, tmp_path
):
    first = vehicle_factory(vehicle_config("first", plugin("tick", TICKER)))
    first.wait_running("tick")
    supervisor = running_supervisor(first.namespace)
    sim = subprocess.run(
        [sys.executable, "-m", "companion", "sim", "--namespace", first.namespace,
         "--state-dir", str(tmp_path / "state"), "--link", "udpout://127.0.0.1:9",
         "--duration", "5"],
        cwd=REPO, capture_output=True, text=True, timeout=100,
    )  # fmt: skip
    assert sim.returncode == EXIT_BUS_IN_USE, sim.stderr
    assert f"is in use by the vehicle of process {supervisor}" in sim.stderr
    assert "sim_bridge" not in sim.stderr  # no simulator started, no clock on that bus
    assert first.proc is not None and first.proc.poll() is None
    assert running_supervisor(first.namespace) == supervisor


@pytest.mark.timeout(60)
def test_a_free_namespace_has_no_supervisor():
    assert running_supervisor("nobody_runs_here") is None
