"""The grid the navigator publishes on (companion/time_grid.py): a state every period, also
when the IMU's stamps wander around the grid's ticks, as they do on an aircraft."""

from __future__ import annotations

import numpy as np

from companion.time_grid import TimeGrid


def _taken(stamps: list[int], rate_hz: float = 50.0) -> list[int]:
    grid = TimeGrid(rate_hz)
    return [t for t in stamps if grid.passed(t)]


def _periods_ms(stamps: list[int], rate_hz: float = 50.0) -> np.ndarray:
    return np.diff(_taken(stamps, rate_hz)) / 1000.0


def _imu(seconds: float, phase_us: float, jitter_us: float, drift_ppm: float = 0.0) -> list[int]:
    """A 100 Hz IMU stamped when its first byte came: its own clock against the board's
    (``drift_ppm``), a phase against the grid, and each stamp a little late or early."""
    rng = np.random.default_rng(7)
    k = np.arange(int(seconds * 100) + 1)
    t = 1_000_000 + phase_us + k * 10_000 * (1 + drift_ppm * 1e-6)
    return [int(x) for x in np.round(t + rng.uniform(-jitter_us, jitter_us, len(t)))]


def test_samples_straddling_the_ticks_still_give_a_state_every_period():
    # The IMU's samples come 0.3 ms either side of the ticks. Taking the first sample at or
    # past each tick, the navigator published at 10, 20 and 30 ms intervals at random.
    periods = _periods_ms(_imu(60.0, phase_us=0.0, jitter_us=300.0))
    assert len(periods) >= 2990
    assert np.all(np.abs(periods - 20.0) < 1.0), sorted(set(np.round(periods)))


def _first_at_or_past_each_tick(stamps: list[int], period_us: int) -> list[int]:
    """The grid's choice before it stayed with the samples (what exact lockstep mirrors)."""
    taken, next_us = [], 0
    for t in stamps:
        if t >= next_us:
            taken.append(t)
            next_us = (t // period_us + 1) * period_us
    return taken


def test_an_imu_clock_drifting_through_the_ticks_costs_a_period_or_two_per_crossing():
    # An IMU clock 250 ppm slow (five times a cheap crystal's error, to cross within a
    # minute): its samples' phase walks 15 ms in 60 s, through the ticks twice.
    stamps = _imu(60.0, phase_us=3_000.0, jitter_us=300.0, drift_ppm=-250.0)
    periods = _periods_ms(stamps)
    odd = int(np.sum(np.abs(periods - 20.0) >= 1.0))
    assert 1 <= odd <= 4, odd
    assert np.all((periods > 9.0) & (periods < 31.0))
    before = np.diff(_first_at_or_past_each_tick(stamps, 20_000)) / 1000.0
    assert np.sum(np.abs(before - 20.0) >= 1.0) >= 20  # 10/30 ms while they straddled


def test_a_simulations_exact_stamps_give_the_first_sample_at_or_past_each_tick():
    # Frames of 10 ms: what the simulator's exact lockstep waits for at each tick.
    stamps = list(range(10_000, 2_000_000, 10_000))
    for rate_hz in (50.0, 25.0, 10.0, 100.0):
        expected = _first_at_or_past_each_tick(stamps, round(1e6 / rate_hz))
        assert _taken(stamps, rate_hz) == expected


def test_after_lost_samples_the_grid_takes_the_next_one_and_keeps_its_ticks():
    stamps = [t for t in range(0, 200_000, 10_000) if not 60_000 <= t <= 90_000]
    assert _taken(stamps) == [0, 20_000, 40_000, 100_000, 120_000, 140_000, 160_000, 180_000]


def test_a_sample_well_before_a_tick_never_completes_it():
    # A 500 Hz IMU: the samples 2 ms before each tick stay in the next period.
    stamps = list(range(2_000, 1_000_000, 2_000))
    assert all(t % 20_000 == 0 for t in _taken(stamps)[1:])
