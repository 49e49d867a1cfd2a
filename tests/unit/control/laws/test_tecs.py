"""Total energy control on a point-mass energy model, and the attitude loops' signs and limits.

The energy model: the flight-path angle follows the demanded pitch less a constant angle of
attack through a 1 s lag; thrust is proportional to throttle (full throttle climbs at about
3 m/s at 30 m/s, trim throttle holds 30 m/s level) and drag to V².
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from companion.control.laws.attitude import AttitudeController, AttitudeGains
from companion.control.laws.tecs import G, Tecs, TecsGains

DT = 0.02
ALPHA = math.radians(3.0)  # angle of attack: pitch = flight-path angle + α
GAMMA_LAG_S = 1.0
CRUISE = 30.0
FULL_THRUST_CLIMB = 3.0  # m/s at full throttle and cruise speed
TRIM = TecsGains().throttle_trim
THRUST_MAX = G * FULL_THRUST_CLIMB / CRUISE / (1.0 - TRIM)  # per unit mass, m/s²
DRAG_K = THRUST_MAX * TRIM / CRUISE**2  # trim throttle balances drag at cruise


@dataclass
class Run:
    times: list[float]
    heights: list[float]
    speeds: list[float]
    pitches: list[float]
    throttles: list[float]


def fly(
    height_dem: float,
    speed_dem: float,
    seconds: float = 60.0,
    gains: TecsGains | None = None,
    height: float = 100.0,
    speed: float = CRUISE,
) -> Run:
    gains = gains or TecsGains()
    tecs = Tecs(gains)
    gamma = 0.0
    run = Run([], [], [], [], [])
    for k in range(round(seconds / DT)):
        climb = speed * math.sin(gamma)
        demand = tecs.step(height, climb, speed, height_dem, speed_dem, DT)
        gamma += (demand.pitch - ALPHA - gamma) * DT / GAMMA_LAG_S
        accel = THRUST_MAX * demand.throttle - DRAG_K * speed * speed - G * math.sin(gamma)
        speed += accel * DT
        height += climb * DT
        run.times.append((k + 1) * DT)
        run.heights.append(height)
        run.speeds.append(speed)
        run.pitches.append(demand.pitch)
        run.throttles.append(demand.throttle)
    return run


def test_climbs_50_m_at_constant_speed_within_60_s():
    gains = TecsGains()
    run = fly(150.0, 30.0, gains=gains)
    assert run.heights[-1] == pytest.approx(150.0, abs=2.0)
    assert run.speeds[-1] == pytest.approx(30.0, abs=1.5)
    assert all(gains.throttle_min <= t <= gains.throttle_max for t in run.throttles)
    assert all(gains.pitch_min <= p <= gains.pitch_max for p in run.pitches)
    # It climbs with the throttle open, not by trading away speed.
    assert max(run.throttles[: round(5 / DT)]) > 0.9
    assert min(run.speeds) > 28.0
    assert max(run.heights) < 153.0  # no large overshoot


@pytest.mark.parametrize(
    ("height_dem", "speed_dem"),
    [(150.0, 30.0), (60.0, 30.0), (100.0, 25.0), (100.0, 35.0), (140.0, 26.0)],
)
def test_reaches_height_and_speed_demands(height_dem: float, speed_dem: float):
    gains = TecsGains()
    run = fly(height_dem, speed_dem, seconds=90.0, gains=gains)
    assert run.heights[-1] == pytest.approx(height_dem, abs=2.0)
    assert run.speeds[-1] == pytest.approx(speed_dem, abs=1.5)
    # Settled: the last 10 s stay close too.
    last = round(10 / DT)
    assert max(abs(h - height_dem) for h in run.heights[-last:]) < 2.0
    assert max(abs(v - speed_dem) for v in run.speeds[-last:]) < 1.5
    assert all(gains.throttle_min <= t <= gains.throttle_max for t in run.throttles)
    assert all(gains.pitch_min <= p <= gains.pitch_max for p in run.pitches)


def test_respects_tighter_limits():
    gains = TecsGains(pitch_max=0.12, pitch_min=-0.1, throttle_min=0.2, throttle_max=0.9)
    run = fly(200.0, 32.0, seconds=30.0, gains=gains)
    assert all(0.2 <= t <= 0.9 for t in run.throttles)
    assert all(-0.1 <= p <= 0.12 for p in run.pitches)
    assert max(run.pitches) == pytest.approx(0.12)  # the limit is reached, not just obeyed


def test_holds_level_at_trim_in_the_steady_state():
    run = fly(100.0, 30.0, seconds=60.0)
    assert run.throttles[-1] == pytest.approx(TRIM, abs=0.02)
    assert run.pitches[-1] == pytest.approx(ALPHA, abs=0.01)  # the integrator found α
    # Only a small sag while it finds the angle of attack, starting from no pitch at all.
    assert max(abs(h - 100.0) for h in run.heights) < 2.0
    assert abs(run.heights[-1] - 100.0) < 0.2


def test_speed_weight_two_leaves_height_to_throttle():
    # Pitch looks only after speed: a height error alone does not move the pitch
    # feed-forward, while a speed error does.
    gains = TecsGains(speed_weight=2.0)
    level = Tecs(gains).step(100.0, 0.0, 30.0, 100.0, 30.0, DT)
    high = Tecs(gains).step(100.0, 0.0, 30.0, 150.0, 30.0, DT)
    fast = Tecs(gains).step(100.0, 0.0, 30.0, 100.0, 35.0, DT)
    assert high.pitch == pytest.approx(level.pitch)
    assert high.throttle > level.throttle + 0.2
    assert fast.pitch < level.pitch - 0.05  # nose down to speed up


def test_height_demand_raises_both_pitch_and_throttle():
    level = Tecs(TecsGains()).step(100.0, 0.0, 30.0, 100.0, 30.0, DT)
    high = Tecs(TecsGains()).step(100.0, 0.0, 30.0, 150.0, 30.0, DT)
    low = Tecs(TecsGains()).step(100.0, 0.0, 30.0, 50.0, 30.0, DT)
    assert high.pitch > level.pitch > low.pitch
    assert high.throttle > level.throttle > low.throttle
    assert level.throttle == pytest.approx(TRIM)


def test_integrators_stay_bounded_under_an_impossible_demand():
    gains = TecsGains()
    tecs = Tecs(gains)
    for _ in range(5_000):  # 100 s of asking for 1 km more with no climb
        demand = tecs.step(100.0, 0.0, 30.0, 1_100.0, 30.0, DT)
        assert gains.pitch_min <= demand.pitch <= gains.pitch_max
        assert gains.throttle_min <= demand.throttle <= gains.throttle_max
    assert -0.3 <= tecs.throttle_integ <= 0.3
    assert gains.pitch_min <= tecs.pitch_integ <= gains.pitch_max


def test_reset_starts_the_pitch_integrator_where_asked():
    tecs = Tecs(TecsGains())
    for _ in range(200):
        tecs.step(100.0, 0.0, 30.0, 200.0, 30.0, DT)
    tecs.reset(pitch=0.1)
    assert tecs.throttle_integ == 0.0 and tecs.pitch_integ == 0.1 and tecs.speed_rate == 0.0


# --- attitude loops ------------------------------------------------------------------------


def still(
    ctl: AttitudeController, roll_dem: float, pitch_dem: float, airspeed: float = 30.0
) -> tuple[float, float, float]:
    s = ctl.step(roll_dem, pitch_dem, (0.0, 0.0), (0.0, 0.0, 0.0), airspeed, DT)
    return s.aileron, s.elevator, s.rudder


def test_roll_error_gives_aileron_of_its_sign():
    right, _, _ = still(AttitudeController(AttitudeGains()), 0.3, 0.0)
    left, _, _ = still(AttitudeController(AttitudeGains()), -0.3, 0.0)
    assert right > 0.2 and left < -0.2
    assert right == pytest.approx(-left)


def test_pitch_error_gives_elevator_of_its_sign():
    _, up, _ = still(AttitudeController(AttitudeGains()), 0.0, 0.1)
    _, down, _ = still(AttitudeController(AttitudeGains()), 0.0, -0.1)
    assert up > 0.1 and down < -0.1


def test_roll_rate_is_damped():
    ctl = AttitudeController(AttitudeGains())
    rolling_right = ctl.step(0.0, 0.0, (0.0, 0.0), (0.5, 0.0, 0.0), 30.0, DT, integrate=False)
    assert rolling_right.aileron < 0.0


def test_banked_turn_asks_for_coordinating_rudder_and_up_elevator():
    ctl = AttitudeController(AttitudeGains())
    bank = math.radians(30.0)
    s = ctl.step(bank, 0.0, (bank, 0.0), (0.0, 0.0, 0.0), 30.0, DT, integrate=False)
    assert s.aileron == pytest.approx(0.0, abs=1e-9)
    assert s.rudder > 0.0  # yaw right with the right bank
    assert s.elevator > 0.0  # the pitch rate a level turn needs
    # Already yawing at the coordinated rate: no rudder.
    r = G / 30.0 * math.sin(bank)
    s = ctl.step(bank, 0.0, (bank, 0.0), (0.0, 0.0, r), 30.0, DT, integrate=False)
    assert s.rudder == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("sign", [+1, -1])
def test_integrators_never_exceed_their_limits(sign: int):
    gains = AttitudeGains()
    ctl = AttitudeController(gains)
    for _ in range(1_000):
        s = ctl.step(sign * 0.5, sign * 0.4, (0.0, 0.0), (0.0, 0.0, 0.0), 12.0, DT)
        assert abs(ctl.roll_integ) <= gains.roll_imax
        assert abs(ctl.pitch_integ) <= gains.pitch_imax
        assert max(abs(s.aileron), abs(s.elevator), abs(s.rudder)) <= 1.0
    # The error lasted long enough to wind them all the way, with its sign.
    assert ctl.roll_integ == pytest.approx(sign * gains.roll_imax)
    assert ctl.pitch_integ == pytest.approx(sign * gains.pitch_imax)
    ctl.reset()
    assert ctl.roll_integ == ctl.pitch_integ == 0.0


def test_integrators_hold_when_told_not_to_integrate():
    ctl = AttitudeController(AttitudeGains())
    for _ in range(100):
        ctl.step(0.5, 0.4, (0.0, 0.0), (0.0, 0.0, 0.0), 30.0, DT, integrate=False)
    assert ctl.roll_integ == 0.0 and ctl.pitch_integ == 0.0


@settings(max_examples=200, deadline=None)
@given(airspeed=st.floats(-50.0, 500.0, allow_nan=False))
def test_scaler_is_bounded(airspeed: float):
    k = AttitudeController(AttitudeGains()).scaler(airspeed)
    assert 0.5 <= k <= 2.0


def test_scaler_is_one_at_the_scaling_speed_and_falls_with_speed():
    ctl = AttitudeController(AttitudeGains(scaling_speed=30.0))
    assert ctl.scaler(30.0) == pytest.approx(1.0)
    assert ctl.scaler(20.0) == pytest.approx(1.5)
    assert ctl.scaler(45.0) == pytest.approx(30.0 / 45.0)
    assert ctl.scaler(0.0) == 2.0 and ctl.scaler(1_000.0) == 0.5
    # And it scales the surface: slower means more aileron for the same error.
    slow, _, _ = still(AttitudeController(AttitudeGains()), 0.1, 0.0, airspeed=20.0)
    fast, _, _ = still(AttitudeController(AttitudeGains()), 0.1, 0.0, airspeed=45.0)
    assert slow > fast > 0.0
