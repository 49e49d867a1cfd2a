"""nav.ins_ekf on synthetic flights with the defects real logs have, one at a time: a start
in the air in a steep bank, a magnetometer that points the wrong way for half a minute, a
GPS whose fixes are late by more than anyone configured."""

from __future__ import annotations

import functools
import math

import numpy as np

from bridges.sensor_models.sensor_errors import NoiseModel
from companion.messages import Magnetometer, NavState
from companion.navigation import rotations
from companion.navigation.ins_ekf import InsEkfConfig
from companion.navigation.offline import InsEkfRunner
from ground.simulation import evaluation
from ground.simulation.synthetic_flight import FlightSpec, Leg
from ground.simulation.synthetic_log import SyntheticFlight, synthesize
from tests.unit.navigation.flights import DECLINATION, OUTAGE, SHORT, flight, fly

# Banked 45° and already turning at the first sample, then rolled hard the other way.
ROLLING_START = (Leg(2, turn_deg_s=-45), Leg(20, turn_deg_s=8), *SHORT[2:])
MAG_OFF = (60.0, 90.0)  # seconds of the flight in which the magnetometer is 60° off


@functools.cache
def rolling_start() -> SyntheticFlight:
    spec = FlightSpec(legs=ROLLING_START, outage=OUTAGE, seed=7, start_turn_deg_s=22.5)
    return synthesize(spec)


def yaw_errors_deg(states: list[NavState], flight_: SyntheticFlight) -> tuple[np.ndarray, ...]:
    """(times s, |yaw error| degrees) of the aligned states."""
    truth = evaluation.truth_columns(flight_)
    aligned = [s for s in states if math.isfinite(s.yaw_rad)]
    t = np.array([s.t_us / 1e6 for s in aligned])
    true_yaw = np.interp(t, truth["t"], np.unwrap(truth["yaw"]))
    err = np.remainder(np.array([s.yaw_rad for s in aligned]) - true_yaw + math.pi, math.tau)
    return t, np.degrees(np.abs(err - math.pi))


def test_the_rolling_start_is_as_steep_as_the_real_logs():
    first = rolling_start().truth[0]
    assert math.degrees(first.roll) > 43.0
    assert abs(first.p) > 1.0  # rad/s


def test_a_start_in_the_air_in_a_steep_rolling_bank_converges():
    errors, states = fly("ins_ekf", rolling_start())
    t, yaw_err = yaw_errors_deg(states, rolling_start())
    assert t[0] < 2.0  # aligned in the air, at once
    assert yaw_err[t > 10.0].max() < 10.0
    assert errors.tilt_rms_deg <= 1.0
    assert errors.yaw_rms_deg <= 3.0
    assert errors.pos_rms_m <= 2.5


def test_a_magnetometer_60_degrees_off_for_30_s_does_not_take_the_heading():
    clean, _ = fly("ins_ekf", flight(), drop={"compass"})
    runner = InsEkfRunner(DECLINATION)
    original = runner.feed
    turned = 0

    def feed(sample):
        nonlocal turned
        if isinstance(sample, Magnetometer) and MAG_OFF[0] * 1e6 < sample.t_us < MAG_OFF[1] * 1e6:
            c, s = math.cos(math.radians(60)), math.sin(math.radians(60))
            x, y = sample.mx_gauss, sample.my_gauss
            sample = Magnetometer(sample.t_us, c * x - s * y, s * x + c * y, sample.mz_gauss)
            turned += 1
        original(sample)

    runner.feed = feed  # type: ignore[method-assign]
    errors, states = fly(runner, flight(), drop={"compass"})
    t, yaw_err = yaw_errors_deg(states, flight())
    assert turned > 1000
    assert yaw_err[t > 10.0].max() < 10.0  # a heading that trusted it would be 60° off
    assert errors.yaw_rms_deg <= clean.yaw_rms_deg + 1.5
    assert runner.nav.mag_monitor.refused > 0


def test_a_gps_0_3_s_late_is_measured_and_compensated_without_configuration():
    lagging = flight(latency=0.3)
    untold = InsEkfRunner(DECLINATION)
    ignored = InsEkfRunner(config=InsEkfConfig(declination_deg=DECLINATION, gps_delay_s=0.0))
    measured, _ = fly(untold, lagging)
    without, _ = fly(ignored, lagging)
    # The filter's own heading soaks up part of a lag in steady turns, so the measured lag
    # comes out short of the truth; most of the error it causes is gone all the same.
    assert 0.15 <= untold.nav.lag.lag_s <= 0.35
    assert measured.pos_rms_m < 0.6 * without.pos_rms_m  # the lag is 7.5 m at 25 m/s
    assert measured.tilt_rms_deg < 0.8 * without.tilt_rms_deg
    assert measured.tilt_rms_deg <= 0.5


def test_a_gps_on_time_is_measured_as_on_time():
    untold = InsEkfRunner(DECLINATION)
    errors, _ = fly(untold, flight())
    assert untold.nav.lag.lag_s <= 0.04
    assert errors.pos_rms_m <= 2.0


def test_a_hard_and_soft_iron_magnetometer_does_not_take_the_heading():
    # 0.15 G against a 0.21 G horizontal field: the magnetometer's heading is up to ~45° off,
    # by an amount that changes with heading, as on the real fixed-wing logs.
    noise = NoiseModel(mag_hard_iron_gauss=(0.15, -0.08, 0.05), mag_soft_iron=(1.1, 0.9, 1.0))
    disturbed = synthesize(FlightSpec(legs=SHORT, outage=OUTAGE, seed=5, noise=noise))
    runner = InsEkfRunner(DECLINATION)
    errors, states = fly(runner, disturbed, drop={"compass"})
    t, yaw_err = yaw_errors_deg(states, disturbed)
    assert yaw_err[t > 10.0].max() < 15.0
    assert errors.yaw_rms_deg <= 4.0
    assert errors.tilt_rms_deg <= 0.8


def test_a_10_hz_point_sampled_imu_on_a_vibrating_airframe():
    noise = NoiseModel(accel_vibration_m_s2=3.0, gyro_vibration_rad_s=0.05)
    shaken = synthesize(FlightSpec(legs=SHORT, outage=OUTAGE, seed=5, imu_hz=10.0, noise=noise))
    errors, _ = fly("ins_ekf", shaken)
    assert errors.tilt_rms_deg <= 1.5
    assert errors.yaw_rms_deg <= 3.0
    assert errors.pos_rms_m <= 3.0
    assert errors.vel_rms_m_s <= 0.5


def test_without_a_declination_the_world_magnetic_model_gives_true_headings():
    # The synthetic field is Melbourne's (11.7° E); nobody tells the navigator so.
    untold = InsEkfRunner()
    errors, _ = fly(untold, flight(), drop={"compass"})
    assert abs(math.degrees(untold.nav.field.declination) - DECLINATION) < 1.0
    assert errors.yaw_rms_deg <= 1.5


def test_a_navigator_that_has_lost_its_heading_finds_it_again():
    runner = InsEkfRunner(DECLINATION)
    original = runner.feed
    done = False

    def feed(sample):
        nonlocal done
        nav = runner.nav
        if not done and nav.aligned and sample.t_us > 40e6:
            # As if it had converged on a heading 90° wrong, and were sure of it.
            _, _, yaw = rotations.quaternion_to_euler(nav.q)
            nav._set_yaw(yaw + math.pi / 2, math.radians(1.0))
            done = True
        original(sample)

    runner.feed = feed  # type: ignore[method-assign]
    _, states = fly(runner, flight(), drop={"compass"})
    t, yaw_err = yaw_errors_deg(states, flight())
    assert done and yaw_err[(t > 40.0) & (t < 41.0)].min() > 60.0
    # The bank of yaw hypotheses learnt the heading from GPS velocity in the turn before;
    # the INS takes it after two seconds of disagreement instead of learning it again.
    assert runner.nav.yaw_resets >= 1
    assert yaw_err[t > 45.0].max() < 10.0
