"""``companion run`` runs the vehicle in the started process, without the command line's
libraries (a plain ``run``: ``companion.launch``; any other: handed over once its options
are checked)."""

from __future__ import annotations

import os
from pathlib import Path

import psutil

from tests.support.configs import pipeline


def _open_files(pid: int) -> list[str]:
    folder = Path(f"/proc/{pid}/fd")
    return [os.readlink(folder / fd) for fd in os.listdir(folder)]


def test_the_vehicle_runs_on_in_the_started_process_without_the_command_lines_libraries(
    vehicle_factory,
):
    vehicle = vehicle_factory(pipeline())
    imu = vehicle.wait_running("imu")
    vehicle.wait_running("relay")
    # The process the user (or a service manager) started is the supervisor: the plug-ins'
    # parent, the one that stops them on SIGTERM.
    assert psutil.Process(imu).ppid() == vehicle.proc.pid
    cmdline = " ".join(psutil.Process(vehicle.proc.pid).cmdline())
    assert " run -c " in cmdline
    pids = vehicle.all_pids()
    assert len(pids) >= 4  # supervisor, fork server, three plug-ins
    for pid in pids:
        # typer converts options with pydantic: its compiled core is the sign it was loaded.
        assert "pydantic_core" not in Path(f"/proc/{pid}/maps").read_text(), pid
        assert not any("companion-handover" in f for f in _open_files(pid)), pid
    assert vehicle.stop() < 2.0
    assert vehicle.proc.returncode == 0
