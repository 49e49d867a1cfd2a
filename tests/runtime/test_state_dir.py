"""The vehicle makes its state directory when it starts (a fresh machine, a new --state-dir),
so the navigator's warm-start file, parameters and missions have somewhere to go."""

from __future__ import annotations

from tests.support.configs import TICKER, plugin, vehicle_config
from tests.support.vehicle import wait_for


def test_a_state_directory_not_made_yet_is_made_at_start(vehicle_factory, tmp_path):
    state = tmp_path / "fresh" / "state"
    vehicle = vehicle_factory(vehicle_config("statedir", plugin("imu", TICKER), state_dir=state))
    vehicle.wait_running("imu")
    wait_for(state.is_dir, 5.0, "the state directory")
