"""The barometer's datum: joins the INS height, is rate-limited, and follows GPS slowly,
standing on the ground only."""

from __future__ import annotations

import pytest

from companion.navigation.baro_datum import BaroDatum


def test_the_first_reading_joins_the_ins_height_and_later_ones_move_with_the_barometer():
    datum = BaroDatum(interval_s=0.1, timeout_s=1.0, tau_s=300.0)
    assert datum.height(12.0, 0, ins_down=-50.0) == pytest.approx(50.0)
    assert datum.height(13.0, 50_000, ins_down=-50.0) is None  # within the interval
    assert datum.height(13.0, 100_000, ins_down=-50.0) == pytest.approx(51.0)
    assert datum.fresh(500_000) and not datum.fresh(1_200_000)


def test_after_a_silence_it_joins_again_where_the_ins_is():
    datum = BaroDatum(interval_s=0.1, timeout_s=1.0, tau_s=300.0)
    datum.height(0.0, 0, ins_down=-10.0)
    assert datum.height(0.0, 5_000_000, ins_down=-30.0) == pytest.approx(30.0)


def test_standing_still_gps_pulls_the_datum_with_its_time_constant():
    datum = BaroDatum(interval_s=0.1, timeout_s=1.0, tau_s=100.0)
    datum.height(0.0, 0, ins_down=-100.0)  # the barometer says 100 m
    for k in range(1, 101):  # GPS says 110 m for 100 s, a fix a second, standing still
        datum.standing(k * 1_000_000)
        datum.follow_gps(-110.0, -100.0, t_us=k * 1_000_000, last_us=(k - 1) * 1_000_000)
    # One time constant against a fixed 10 m disagreement: 10 m, not more, not at once.
    assert datum.offset == pytest.approx(100.0 + 10.0, abs=0.01)
    datum.follow_gps(float("nan"), -100.0, t_us=101_000_000, last_us=100_000_000)
    assert datum.offset == pytest.approx(110.0, abs=0.01)


def test_moving_gps_does_not_move_the_datum():
    """GPS height wanders by metres over minutes: in flight the height above home (taken
    at arming) must stay the barometer's. Pulled along with a 300 s time constant, the
    J3Cub's height read 3.2 m high at arming and its glide path lay 3.2 m high."""
    datum = BaroDatum(interval_s=0.1, timeout_s=1.0, tau_s=300.0)
    datum.height(0.0, 0, ins_down=-100.0)
    datum.standing(1_000_000)
    for k in range(4, 600):  # found still last at 1 s; GPS 8 m higher for ten minutes
        datum.follow_gps(-108.0, -100.0, t_us=k * 1_000_000, last_us=(k - 1) * 1_000_000)
    assert datum.offset == 100.0
    datum.standing(600_000_000)  # landed and standing: GPS may set the datum again
    datum.follow_gps(-108.0, -100.0, t_us=601_000_000, last_us=600_000_000)
    assert datum.offset == pytest.approx(100.0 + 8.0 / 300.0)


def test_a_barometer_that_starts_counting_from_zero_again_does_not_move_the_height():
    """Its driver restarted in the air (the IMU's plug-in killed): 100 m above its old zero
    it now reads 0. In lockstep the navigator's height fell 97 m with it, and the controller
    climbed 24 m after the wrong height."""
    datum = BaroDatum(interval_s=0.1, timeout_s=1.0, tau_s=300.0)
    datum.height(100.0, 0, ins_down=-480.0)
    assert datum.height(100.5, 100_000, ins_down=-480.5) == pytest.approx(480.5)
    assert datum.height(0.2, 200_000, ins_down=-480.5) == pytest.approx(480.5)  # the same
    assert datum.height(1.2, 300_000, ins_down=-481.0) == pytest.approx(481.5)  # then moves
