"""sensors.rc_input after kill -9 and after the whole vehicle restarts, on the same pty: the
new process opens the port the old one left at 100000 8E2 and the sticks come through
again (pyserial 3.5 alone failed that open with termios.error 22, and restarted for ever)."""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import time

import pytest

from tests.support.configs import plugin, vehicle_config
from tests.support.pty import Pty
from tests.support.sbus import frame, us_to_raw
from tests.support.vehicle import Vehicle, wait_for

KILLS = 2


def roll_frame(roll_us: int) -> bytes:
    ch = [us_to_raw(1500)] * 16
    ch[0], ch[2] = us_to_raw(roll_us), us_to_raw(1500)  # throttle above its failsafe value
    return frame(ch)


def sticks_flow(vehicle: Vehicle, pty: Pty, roll_us: int, what: str) -> None:
    """Frames with this roll are decoded and published on sensors/rc."""
    assert vehicle.bus is not None
    sticks = vehicle.bus.latest_reader("sensors/rc")

    def seen() -> bool:
        # Non-blocking: a port nobody reads (a process that failed to open it) fills up,
        # and a blocked write would hang the test instead of failing it.
        os.set_blocking(pty.master, False)
        with contextlib.suppress(BlockingIOError):
            os.write(pty.master, roll_frame(roll_us) * 2)
        got = sticks.get()
        return got is not None and got.usable() and abs(got.channels_us[0] - roll_us) <= 2

    wait_for(seen, 60, what)  # a minute, as on a busy machine


@pytest.mark.timeout(300)
def test_kill_9_of_the_rc_plugin_the_restarted_process_decodes_sbus_again(
    vehicle_factory, tmp_path
):
    pty = Pty(tmp_path / "ttyRC")
    rc = plugin("rc", "sensors.rc_input", device=str(pty.link))
    vehicle = vehicle_factory(vehicle_config("rc", rc))
    pid = vehicle.wait_running("rc")
    sticks_flow(vehicle, pty, 1900, "full right roll from the first process")
    for kill in range(1, KILLS + 1):
        killed_at = time.monotonic()
        os.kill(pid, signal.SIGKILL)
        pid = wait_for(
            lambda old=pid: (r := vehicle.row("rc")) and r.pid not in (0, old) and r.pid,
            30,
            f"the rc plug-in's process after kill {kill}",
        )
        roll_us = 1100 if kill % 2 else 1900
        sticks_flow(vehicle, pty, roll_us, f"sticks from the process after kill {kill}")
        logging.getLogger(__name__).info(
            "kill %d: sticks again %.2f s after the kill", kill, time.monotonic() - killed_at
        )
    # Each kill restarted it once: the new process did not die opening the port.
    assert vehicle.row("rc").restarts == KILLS
    assert vehicle.row("rc").pid == pid
    pty.vanish()


@pytest.mark.timeout(300)
def test_a_vehicle_started_again_on_the_same_pty_reads_its_receiver(vehicle_factory, tmp_path):
    """A service restart (SIGTERM), then a power cut (SIGKILL of every process), then a
    third start: the port each one found as the last left it."""
    pty = Pty(tmp_path / "ttyRC")
    rc = plugin("rc", "sensors.rc_input", device=str(pty.link))
    for start, roll_us in enumerate((1900, 1100, 1700)):
        vehicle = vehicle_factory(vehicle_config("rc", rc))
        vehicle.wait_running("rc")
        sticks_flow(vehicle, pty, roll_us, f"sticks after start {start + 1}")
        assert vehicle.row("rc").restarts == 0
        if start == 0:
            vehicle.stop()
        else:
            for pid in vehicle.all_pids():
                os.kill(pid, signal.SIGKILL)
            assert vehicle.proc is not None
            vehicle.proc.wait(timeout=10)
        vehicle.close()
    pty.vanish()
