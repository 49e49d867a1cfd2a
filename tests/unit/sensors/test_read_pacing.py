"""How long a driver lets its frames pile up: a batch of vehicle time, on the wall clock as
fast as vehicle time runs, never longer than the batch itself."""

from __future__ import annotations

import pytest

from companion.control.modes import PILOT_MODES
from companion.messages import FlightMode, VehicleStatus
from companion.plugins.sensors.rangefinder import Rangefinder
from companion.plugins.sensors.rc_input import _pilot_flies
from companion.sensors.read_pacing import ReadPacer


def test_on_a_real_clock_the_next_read_comes_a_batch_after_the_last():
    pacer = ReadPacer(0.1)
    assert pacer.pause_s(0) == 0.0  # nothing read yet: read at once
    pacer.read_at(1_000_000, 50.0)
    pacer.read_at(1_100_000, 50.1)
    assert pacer.pause_s(1_130_000) == pytest.approx(0.07)
    assert pacer.pause_s(1_250_000) == 0.0  # late already: read at once


def test_a_simulation_eight_times_faster_than_real_time_waits_an_eighth():
    pacer = ReadPacer(0.1)
    pacer.read_at(0, 10.0)
    pacer.read_at(800_000, 10.1)  # 0.8 s of vehicle time in 0.1 s of wall
    assert pacer.pause_s(800_000) == pytest.approx(0.1 / 8)


def test_a_held_simulation_does_not_stretch_a_batch_past_its_length():
    pacer = ReadPacer(0.1)
    pacer.read_at(0, 10.0)
    pacer.read_at(10_000, 12.0)  # vehicle time crawled: a late process held it
    assert pacer.pause_s(10_000) == pytest.approx(0.1)


def test_no_batch_reads_each_frame():
    pacer = ReadPacer(0.0)
    pacer.read_at(0, 1.0)
    assert pacer.pause_s(0) == 0.0


def _status(mode: FlightMode, armed: bool) -> VehicleStatus:
    return VehicleStatus(t_us=0, mode=int(mode), armed=int(armed))


@pytest.mark.parametrize("mode", list(FlightMode))
def test_the_receiver_is_read_frame_by_frame_only_while_the_pilot_flies(mode):
    assert _pilot_flies(_status(mode, armed=True)) == (mode in PILOT_MODES)
    assert not _pilot_flies(_status(mode, armed=False))


def test_the_rangefinder_is_read_frame_by_frame_armed_with_the_ground_in_view():
    sensor = Rangefinder()
    armed, disarmed = _status(FlightMode.MISSION, True), _status(FlightMode.MISSION, False)
    sensor.ground_in_view = False  # cruising above its range
    assert not sensor.per_frame(armed)
    sensor.ground_in_view = True  # take-off roll, approach, flare
    assert sensor.per_frame(armed)
    assert not sensor.per_frame(disarmed)  # on the bench


def test_a_deadline_in_vehicle_time_is_waited_for_at_the_pace_the_simulation_runs():
    pacer = ReadPacer(0.0)  # the commander's: no batch, its own deadlines
    assert pacer.wall_s_until(100_000, 0) == pytest.approx(0.1)  # no pace yet: real time
    pacer.read_at(0, 10.0)
    pacer.read_at(400_000, 10.1)  # four times faster than real time
    assert pacer.wall_s_until(500_000, 400_000) == pytest.approx(0.025)
    assert pacer.wall_s_until(300_000, 400_000) == 0.0  # already past
