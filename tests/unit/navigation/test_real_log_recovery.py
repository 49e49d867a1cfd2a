"""On real flights, a navigator knocked 90° off its heading mid-flight has it back within
seconds from the GPS-velocity yaw estimator bank, and the bank never overrides a navigator
that is right (the real-log set of ``test_change_indication``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from companion.navigation import rotations
from companion.navigation.offline import InsEkfRunner, run_navigator
from companion.sensors.sensorlog import read_sensor_log
from tests.unit.navigation.test_change_indication import NAVLOGS

KNOCK_S = 40.0


def reference_yaw(name: str) -> tuple[np.ndarray, np.ndarray]:
    data = np.genfromtxt(NAVLOGS / f"{name}.reference.csv", delimiter=",", names=True)
    return data["t"], np.unwrap(data["yaw"])


def replay(name: str, knock: bool) -> tuple[InsEkfRunner, np.ndarray, np.ndarray]:
    """(runner, times s, |yaw error| °) of a replay, knocked 90° at KNOCK_S if asked."""
    runner = InsEkfRunner()
    original = runner.feed
    knocked = not knock

    def feed(sample):
        nonlocal knocked
        nav = runner.nav
        if not knocked and nav.aligned and sample.t_us > KNOCK_S * 1e6:
            _, _, yaw = rotations.quaternion_to_euler(nav.q)
            nav._set_yaw(yaw + math.pi / 2, math.radians(1.0))  # and sure of it
            knocked = True
        original(sample)

    runner.feed = feed  # type: ignore[method-assign]
    samples = read_sensor_log(NAVLOGS / f"{name}.sensors.csv")
    states = [s for s in run_navigator(runner, samples, rate_hz=10.0) if math.isfinite(s.yaw_rad)]
    t = np.array([s.t_us / 1e6 for s in states])
    ref_t, ref_yaw = reference_yaw(name)
    inside = (t >= ref_t[0] + 10.0) & (t <= ref_t[-1])
    err = np.array([s.yaw_rad for s in states]) - np.interp(t, ref_t, ref_yaw)
    err = np.degrees(np.abs(np.remainder(err + math.pi, math.tau) - math.pi))
    return runner, t[inside], err[inside]


@pytest.mark.parametrize("name", ["plane_alfa_1005_nofail", "copter_px4_0621"])
def test_a_heading_knocked_90_degrees_off_in_flight_is_back_within_seconds(name: str):
    if not (NAVLOGS / f"{name}.sensors.csv").is_file():
        pytest.skip(f"the real-log set is not beside the project ({NAVLOGS})")
    runner, t, err = replay(name, knock=True)
    assert err[(t > KNOCK_S) & (t < KNOCK_S + 0.5)].min() > 60.0
    assert runner.nav.yaw_resets >= 1
    assert err[t > KNOCK_S + 5.0].max() < 15.0


def test_the_bank_leaves_a_right_heading_alone():
    name = "plane_alfa_1005_aileron"  # the magnetometer 69° off, the bank 17° off at worst
    if not (NAVLOGS / f"{name}.sensors.csv").is_file():
        pytest.skip(f"the real-log set is not beside the project ({NAVLOGS})")
    runner, _, err = replay(name, knock=False)
    assert runner.nav.yaw_resets == 0
    assert err.max() < 10.0
