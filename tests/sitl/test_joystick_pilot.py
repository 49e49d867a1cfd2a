"""QGroundControl's joystick (MAVLink MANUAL_CONTROL, sent here by pymavlink) flies Manual,
out-of-range axes are refused, and a joystick that stops brings the aircraft home.

The simulation runs in real time (a joystick is a person at a ground station, sending at
wall-clock rates) with the RC receiver silent, so the joystick is the only pilot.
"""

from __future__ import annotations

import time

import pytest

from companion.messages import FlightMode
from mavlink_dialect import companion as d
from tests.protocol.mav_client import free_udp_port
from tests.sim.sim_run import finish, start_sim
from tests.sitl.pilot_logs import (
    first_entry,
    joystick_times,
    matches,
    mode_changes,
    servo_rows,
)
from tests.sitl.test_failsafes import Station

RC_OVERRIDE_TIME = 3.0  # ArduPilot's default, and ours
# Stick forward (x +) is nose down: x = -400 is the pitch stick 40 % back, nose up.
JOYSTICK = {"x": -400, "y": 500, "z": 700, "r": 0}
SURFACES = {"aileron": 0.5, "elevator": 0.4, "rudder": 0.0, "throttle": 0.7}


class Joystick(Station):
    """A ground station that also sends MANUAL_CONTROL 20 times a second while asked to."""

    def __init__(self, port: int) -> None:
        super().__init__(f"udpin:127.0.0.1:{port}")
        self.axes: dict[str, int] | None = None
        self._next_stick = 0.0

    def pump(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if self.axes is not None and time.monotonic() >= self._next_stick:
                a = self.axes
                self.conn.mav.manual_control_send(1, a["x"], a["y"], a["z"], a["r"], 0)
                self._next_stick = time.monotonic() + 0.05
            super().pump(0.05)


@pytest.mark.timeout(300)
def test_joystick_flies_manual_and_its_loss_returns_home(tmp_path):
    pilot = tmp_path / "pilot.csv"
    pilot.write_text("t,signal\n0,silent\n")  # the receiver never speaks
    servo_log = tmp_path / "servos.csv"
    port = free_udp_port()
    station = Joystick(port)
    proc, namespace, _ = start_sim(
        tmp_path, f"udpout://127.0.0.1:{port}", "--speed", "1", "--airborne",
        "--duration", "300", "--pilot", str(pilot), "--servo-log", str(servo_log),
    )  # fmt: skip
    try:
        # QGroundControl sends its joystick's sticks from the moment it is enabled, armed or
        # not; with the receiver silent, they are what lets the pre-arm checks pass.
        station.axes = dict(JOYSTICK)
        station.until(lambda: station.mode >= 0, 60, "the vehicle heard")
        arm = d.MAV_CMD_COMPONENT_ARM_DISARM
        station.until(lambda: station.acked(arm, 1) == d.MAV_RESULT_ACCEPTED, 60, "armed")
        station.axes = dict(JOYSTICK)
        station.pump(1.0)
        manual = (d.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 0)  # ArduPlane MANUAL, as MAVProxy
        assert station.acked(d.MAV_CMD_DO_SET_MODE, *manual) == d.MAV_RESULT_ACCEPTED
        station.until(lambda: station.in_mode(FlightMode.MANUAL), 10, "in Manual")
        station.pump(3.0)
        station.axes = {**JOYSTICK, "x": 30000}  # past full travel: refused, not flown
        station.until(lambda: station.said("MANUAL_CONTROL refused"), 10, "told of the refusal")
        station.axes = None  # the joystick is unplugged
        station.until(lambda: station.in_mode(FlightMode.RTL), 30, "returning")
        assert station.said("joystick lost")
    finally:
        proc.terminate()
        finish(proc, namespace, 60)
        station.conn.close()

    modes = mode_changes(tmp_path / "state")
    t_manual = first_entry(modes, FlightMode.MANUAL, 0.0)
    t_rtl = first_entry(modes, FlightMode.RTL, t_manual)
    servos = servo_rows(servo_log)
    flown = [s for t, s in servos if t_manual <= t < t_rtl]
    assert any(matches(s, SURFACES) for s in flown)
    assert not any(s.get("elevator", 0.0) < -0.9 for s in flown)  # x = 30000 never flown
    assert [m for t, m in modes if t_manual <= t < t_rtl] == [FlightMode.MANUAL]
    # Home once the last accepted sticks are RC_OVERRIDE_TIME old (judged ten times a
    # vehicle second; the refused ones do not count as a pilot).
    last_sticks = max(t for t in joystick_times(tmp_path / "state") if t < t_rtl)
    waited = round(t_rtl - last_sticks, 6)  # the logs' seconds differ by float rounding
    assert RC_OVERRIDE_TIME <= waited <= RC_OVERRIDE_TIME + 2.0, waited
