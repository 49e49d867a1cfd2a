"""The flare's aim (companion/control/flight/flare_aim.py): the sink demand whose
exponential flare touches down on the point, the time to the point as the aircraft
slows, and the least pitch of a flare flown faster than the approach."""

from __future__ import annotations

import math

import pytest

from companion.control.flight.flare_aim import (
    DecelEstimate,
    aimed_sink,
    fast_pitch_drop,
    flare_pitch,
    time_to_point,
)

SINK = 0.4  # TECS_LAND_SINK


def _flown(height: float, speed: float, decel: float, sink_of, dt: float = 0.01) -> float:
    """Where a point mass that sinks as ``sink_of(height, to_go)`` asks meets the ground,
    from 100 m before the point (+ past it)."""
    along, h = -100.0, height
    while h > 0.0 and speed > 1.0:
        h -= sink_of(h, -along, speed) * dt
        along += speed * dt
        speed -= decel * dt
    return along


@pytest.mark.parametrize("decel", [0.0, 1.5])
@pytest.mark.parametrize("height", [3.0, 5.0, 8.0])
def test_the_aimed_flare_touches_down_on_the_point_slowing_or_not(height: float, decel: float):
    def aimed(h: float, to_go: float, speed: float) -> float:
        return min(aimed_sink(h, time_to_point(to_go, speed, decel), SINK), 20.0)

    assert _flown(height, 28.0, decel, aimed) == pytest.approx(0.0, abs=1.5)


def test_the_aim_is_the_exponential_flare_and_floats_no_slower_than_the_touchdown_sink():
    for tau in (1.0, 2.0, 4.0):
        t = tau * math.log1p(5.0 / (SINK * tau))
        assert aimed_sink(5.0, t, SINK) == pytest.approx(SINK + 5.0 / tau, rel=1e-6)
    assert aimed_sink(5.0, 60.0, SINK) == SINK  # beyond reach: float at the touchdown sink
    assert aimed_sink(5.0, 0.0, SINK) == math.inf  # passed: get down


def test_time_to_point_counts_the_speed_lost_and_a_stop_before_it():
    assert time_to_point(100.0, 25.0, 0.0) == pytest.approx(4.0)
    assert time_to_point(100.0, 25.0, 2.0) > 4.0
    assert time_to_point(100.0, 10.0, 2.0) == math.inf
    assert time_to_point(-5.0, 25.0, 0.0) == 0.0


def test_the_deceleration_is_measured_smoothed_and_a_gust_spike_bounded():
    est = DecelEstimate()
    speed = 30.0
    for _ in range(300):
        est.update(speed, 0.02)
        speed -= 2.0 * 0.02
    assert est.decel == pytest.approx(2.0, abs=0.05)
    est.update(speed + 50.0, 0.02)  # a jump no aircraft flies: clipped before smoothing
    assert est.decel > 1.8 - 0.02 * 5.0 / 1.0


def test_a_faster_flare_may_pitch_lower_by_the_angle_of_attack_its_extra_lift_makes_up():
    # Lift goes as V²·(α - α0): at 28 m/s a wing 6° above zero lift at 22 m/s holds the
    # same lift 6°·(1 - (22/28)²) = 2.3° lower.
    assert fast_pitch_drop(28.0, 22.0, 6.0) == pytest.approx(math.radians(2.3), abs=1e-3)
    assert fast_pitch_drop(22.0, 22.0, 6.0) == 0.0  # at the approach speed, and slower
    assert fast_pitch_drop(18.0, 22.0, 6.0) == 0.0
    assert fast_pitch_drop(28.0, 22.0, 0.0) == 0.0  # LAND_FLARE_AOA 0: off
    assert fast_pitch_drop(math.nan, 22.0, 6.0) == 0.0  # no airspeed known
    assert fast_pitch_drop(80.0, 22.0, 6.0) == pytest.approx(math.radians(3.0))  # a spike: half
    v = {"LAND_PITCH_CD": -400.0, "TECS_LAND_PMAX": 10.0, "TECS_LAND_ARSPD": 22.0,
         "LAND_FLARE_AOA": 6.0}  # fmt: skip
    assert flare_pitch(-1.0, 28.0, v) == pytest.approx(math.radians(-6.3), abs=1e-3)
    assert flare_pitch(-1.0, 22.0, v) == pytest.approx(math.radians(-4.0))
    assert flare_pitch(-0.05, 28.0, v) == -0.05
    assert flare_pitch(1.0, 28.0, v) == pytest.approx(math.radians(10.0))
