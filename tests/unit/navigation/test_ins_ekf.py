"""nav.ins_ekf's navigator on synthetic flights with realistic noise, biases and an outage."""

from __future__ import annotations

import dataclasses
import math

import pytest

from bridges.sensor_models.sensor_errors import NoiseModel
from companion.messages import GpsFix, Imu, NavFlags
from companion.navigation.ins_ekf import InsEkfConfig
from companion.navigation.offline import NAVIGATORS, InsEkfRunner, run_navigator, true_headings
from ground.simulation.evaluation import messages
from ground.simulation.synthetic_flight import FlightSpec, Leg
from ground.simulation.synthetic_log import synthesize
from tests.unit.navigation.flights import DECLINATION, OUTAGE, SHORT, flight, fly, perfect_baro


def test_meets_the_accuracy_targets_and_bridges_a_30_s_outage():
    errors, states = fly("ins_ekf", flight())
    assert errors.tilt_rms_deg <= 0.5
    assert errors.yaw_rms_deg <= 2.0
    assert errors.pos_rms_m <= 2.0
    assert errors.vel_rms_m_s <= 0.3
    assert errors.outage_end_m <= 30.0
    # The outage is visible in the solution: flagged, and its uncertainty grows, then shrinks.
    start, length = (t * 1e6 for t in OUTAGE)
    inside = [s for s in states if start + 3e6 < s.t_us < start + length]
    after = [s for s in states if s.t_us > start + length + 10e6]
    assert inside and all(s.flags & NavFlags.DEAD_RECKONING for s in inside)
    assert inside[-1].pos_std_m[0] > 3 * inside[0].pos_std_m[0]
    assert not after[-1].flags & NavFlags.DEAD_RECKONING
    assert after[-1].pos_std_m[0] < 2.0


def test_beats_the_thesis_navigator_whose_compass_tilts_in_turns():
    ins, _ = fly("ins_ekf", flight())
    thesis, _ = fly("gps_compass", flight())
    assert thesis.tilt_rms_deg > 3 * ins.tilt_rms_deg
    assert thesis.outage_end_m > ins.outage_end_m


def test_a_slow_imu_and_a_lagging_gps_with_its_delay_configured():
    lagging = flight(imu_hz=20.0, latency=0.2)
    runner = InsEkfRunner(config=InsEkfConfig(declination_deg=DECLINATION, gps_delay_s=0.2))
    errors, _ = fly(runner, lagging)
    assert errors.tilt_rms_deg <= 0.8
    assert errors.pos_rms_m <= 2.5
    assert errors.outage_end_m <= 40.0


def test_compass_alone_gives_a_usable_heading():
    errors, _ = fly("ins_ekf", flight(), drop={"mag"})
    assert errors.yaw_rms_deg <= 3.0
    assert errors.tilt_rms_deg <= 0.8


def test_no_heading_sensor_at_all_aligns_from_the_gps_course_in_flight():
    errors, states = fly("ins_ekf", flight(), drop={"mag", "compass"})
    aligned = [s for s in states if not s.flags & NavFlags.ALIGNING]
    assert aligned and aligned[0].t_us < 2e6  # started in the air, aligned at once
    assert errors.yaw_rms_deg <= 3.0  # the turns make heading observable through GPS


def test_gps_outliers_are_rejected_counted_and_do_not_move_the_solution():
    clean, _ = fly("ins_ekf", flight())
    runner = InsEkfRunner(DECLINATION)
    bad = 0
    original = runner.feed

    def feed(sample):
        nonlocal bad
        if isinstance(sample, GpsFix) and 60e6 < sample.t_us < 62e6:
            sample = GpsFix.from_buffer_copy(sample)
            sample.lat_deg += 0.002  # 220 m north: a multipath jump
            bad += 1
        original(sample)

    runner.feed = feed  # type: ignore[method-assign]
    errors, states = fly(runner, flight())
    assert bad >= 5 and states[-1].gps_rejected >= bad
    assert errors.pos_p95_m <= clean.pos_p95_m + 1.0


def test_a_hole_in_the_imu_data_is_survived():
    runner = InsEkfRunner(DECLINATION)
    errors, _ = fly(runner, flight(), drop=set())
    nav = runner.nav
    t = nav.t_us
    nav.on_imu(Imu(t + 2_000_000, 0.0, 0.0, -9.8, 0.0, 0.0, 0.0, math.nan))  # 2 s later
    nav.on_imu(Imu(t + 2_010_000, 0.0, 0.0, -9.8, 0.0, 0.0, 0.0, math.nan))
    assert nav.state().t_us == t + 2_010_000
    assert math.isfinite(nav.state().lat_deg)
    assert errors.pos_rms_m <= 2.0


def test_the_config_is_a_plain_record():
    config = dataclasses.replace(InsEkfConfig(), gyro_noise=1e-3)
    assert config.gyro_noise == 1e-3 and InsEkfConfig().gyro_noise == pytest.approx(5e-4)


def test_height_holds_kilometres_from_where_the_frame_was_set():
    """The barometer measures height over the curved Earth and the navigator's frame is a
    plane: a straight 7 km leg out and back, perfect sensors and a barometer, must keep
    the height to decimetres, not drift by the Earth's fall-away (3.8 m at 7 km; 1.9 m
    above the truth 6 km out in a simulated zigzag before the barometer was placed)."""
    legs = (Leg(280, speed_m_s=25.0), Leg(7.2, turn_deg_s=25.0), Leg(280, speed_m_s=25.0))
    spec = FlightSpec(legs=legs, heading_deg=0.0, noise=NoiseModel(scale=0.0), seed=3)
    synthetic = synthesize(spec)
    baro = perfect_baro(synthetic)
    sensors = sorted(messages(synthetic) + baro, key=lambda m: m.t_us)
    nav = NAVIGATORS["ins_ekf"](DECLINATION)
    states = list(run_navigator(nav, true_headings(sensors, DECLINATION)))
    truth = {round(s.t_s * 1e6): s.alt_msl_m for s in synthetic.truth}
    errors = [abs(s.alt_msl_m - truth[s.t_us]) for s in states if s.t_us in truth]
    late = errors[len(errors) // 10 :]  # after the start-up
    assert len(late) > 1000 and max(late) < 0.3, max(late)


def _rtk_runner(floor_m: float | None = None) -> InsEkfRunner:
    """The navigator fed fixes as the NMEA driver decodes an RTK-fixed receiver's: 1.2 cm."""
    config = InsEkfConfig(declination_deg=DECLINATION)
    if floor_m is not None:
        config = dataclasses.replace(config, gps_pos_min_std=floor_m)
    runner = InsEkfRunner(config=config)
    original = runner.feed

    def feed(sample):
        if isinstance(sample, GpsFix):
            sample = GpsFix.from_buffer_copy(sample)
            sample.eph_m, sample.fix_type = 0.012, 6
        original(sample)

    runner.feed = feed  # type: ignore[method-assign]
    return runner


def test_an_rtk_receiver_puts_the_solution_within_centimetres_of_the_truth():
    rtk = synthesize(FlightSpec(legs=SHORT, outage=OUTAGE, seed=5, noise=NoiseModel().with_rtk()))
    errors, states = fly(_rtk_runner(), rtk)
    assert errors.pos_rms_m <= 0.1 and errors.vel_rms_m_s <= 0.1
    assert states[-1].gps_rejected == 0
    # Fused at the centimetre it claims, the IMU's propagation between fixes reads as the
    # GPS's error: fixes are refused as outliers and the solution falls apart.
    errors, states = fly(_rtk_runner(floor_m=0.001), rtk)
    assert states[-1].gps_rejected > 100 and errors.pos_rms_m > 1.0


@pytest.mark.parametrize(
    ("eph_m", "fused_m"), [(2.25, 2.25), (0.012, 0.3), (math.nan, 3.0), (math.inf, 3.0), (0, 3.0)]
)
def test_a_fix_is_fused_with_its_own_accuracy_at_least_the_floor(eph_m, fused_m):
    assert InsEkfConfig().fix_pos_std(eph_m) == fused_m
