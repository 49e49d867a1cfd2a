"""The landing score reads one landing from a truth record: where and how hard the wheels
met the runway, and where the aircraft stopped."""

from __future__ import annotations

import numpy as np
import pytest

from bridges.jsbsim.truth_log import WheelLog, wheels_path
from companion.geodesy import LocalFrame
from companion.navigation.estimate_csv import EstimateWriter
from ground.campaign.landing_score import line_coordinates, read_truth, score_landing

LAND = (-37.9105, 145.134)
APPROACH = (-37.9105, 145.110)  # west of the touchdown point: the approach flies east
REST_M = 81.3
DT = 0.1


def landing_truth(touch_east_m: float, parked_s: float) -> dict[str, np.ndarray]:
    """Parked on the runway (where the record starts), then a descent east at 30 m/s and
    2 m/s down, wheels on at ``touch_east_m`` of the target, 1.5 m/s² of braking to a stop,
    then ``parked_s`` standing still."""
    t_air = 40.0
    t_roll = 30.0 / 1.5
    t = np.arange(0.0, t_air + t_roll + parked_s, DT)
    air = t < t_air
    rolling = (t >= t_air) & (t < t_air + t_roll)
    speed = np.where(air, 30.0, np.where(rolling, 30.0 - 1.5 * (t - t_air), 0.0))
    east = touch_east_m + np.cumsum(speed) * DT - 30.0 * t_air
    alt = REST_M + np.where(air, 1.2 * (t_air - t), 0.0)
    air[0], alt[0], speed[0] = False, REST_M, 0.0
    vd = np.where(air, 1.2, 0.0)
    lat, lon = LocalFrame(*LAND).latlon(np.zeros_like(east), east)
    zeros = np.zeros_like(t)
    return {
        "t": t, "lat": lat, "lon": lon, "alt": alt, "vn": zeros, "ve": speed, "vd": vd,
        "roll": zeros, "pitch": zeros, "yaw": zeros + np.pi / 2,
    }  # fmt: skip


def test_a_landing_is_scored_where_the_wheels_met_the_runway():
    score = score_landing(landing_truth(12.0, 10.0), APPROACH, LAND)
    assert score.landed and score.stopped and score.on_runway
    assert score.along_m == pytest.approx(12.0, abs=4.0)
    assert score.sink_m_s == pytest.approx(1.2)
    assert score.passed()


def test_what_a_simulator_does_with_the_parked_aircraft_afterwards_is_not_the_landing():
    # Left running after the disarm, a simulation once tumbled the parked aircraft 100 s
    # later: up to 150 m, down at 28 m/s, 300 m off the runway. The landing was before.
    truth = landing_truth(12.0, 120.0)
    late = truth["t"] > truth["t"][-1] - 20.0
    tumble = REST_M + 70.0 * np.sin(np.pi * (truth["t"] - truth["t"][-1]) / 20.0) ** 2
    truth["alt"] = np.where(late, tumble, truth["alt"])
    truth["vd"] = np.where(late, 28.0, truth["vd"])
    truth["vn"] = np.where(late, 15.0, truth["vn"])
    score = score_landing(truth, APPROACH, LAND)
    assert score.along_m == pytest.approx(12.0, abs=4.0)
    assert score.sink_m_s == pytest.approx(1.2)
    assert score.passed(), score


def test_a_position_is_measured_along_and_across_the_landing_line():
    """What the benchmark reads the navigator's track by: 3 m south of an eastbound
    runway is 3 m right of it, 20 m east of the point 20 m past it."""
    lat, lon = LocalFrame(*LAND).latlon(np.array([-3.0]), np.array([20.0]))
    along, across = line_coordinates(lat, lon, APPROACH, LAND)
    assert along[0] == pytest.approx(20.0, abs=0.01)
    assert across[0] == pytest.approx(3.0, abs=0.01)


def skimming_truth() -> tuple[dict[str, np.ndarray], np.ndarray]:
    """A flare that levels 0.4 m above the runway for 20 m before the wheels touch at +12 m
    (what a C172 does in JSBSim): the centre of gravity is back near its resting height and
    no longer sinking while the wheels still carry nothing."""
    truth = landing_truth(12.0, 10.0)
    east = LocalFrame(*LAND).ne(truth["lat"], truth["lon"])[1]
    skim = (east > -8.0) & (east < 12.0)
    truth["alt"] = np.where(skim, REST_M + 0.4, truth["alt"])
    truth["vd"] = np.where(skim, 0.0, truth["vd"])
    return truth, east


def test_a_skim_above_the_runway_is_not_the_touchdown_when_the_wheel_contacts_are_known():
    truth, east = skimming_truth()
    by_height = score_landing(truth, APPROACH, LAND)
    assert by_height.along_m == pytest.approx(-8.0, abs=4.0)  # what the height alone says
    truth["on_wheels"] = ((east >= 12.0) | (truth["t"] == 0.0)).astype(float)
    score = score_landing(truth, APPROACH, LAND)
    assert score.along_m == pytest.approx(12.0, abs=4.0)
    assert score.passed(), score


def test_the_simulators_wheel_contacts_are_read_beside_its_truth_file(tmp_path):
    truth_path = tmp_path / "truth.csv"
    writer = EstimateWriter(truth_path)
    for k in range(10):
        writer.add(k * 0.5, 0, 0, 0, LAND[0], LAND[1], REST_M, 0, 0, 0)
    writer.close()
    wheels = WheelLog(wheels_path(truth_path))
    for k in range(10):  # on the wheels, off from 1 s, on again from 3 s
        wheels.add(k * 0.5, not 1.0 <= k * 0.5 < 3.0)
    wheels.close()
    assert wheels_path(truth_path).read_text().split() == [
        "t,on_wheels", "0.0000,1", "1.0000,0", "3.0000,1"
    ]  # fmt: skip
    assert list(read_truth(truth_path)["on_wheels"]) == [1, 1, 0, 0, 0, 0, 1, 1, 1, 1]
    wheels_path(truth_path).unlink()  # an older simulator's record: the height decides
    assert "on_wheels" not in read_truth(truth_path)
