"""Fixtures shared by the protocol tests."""

from __future__ import annotations

import pytest

from tests.protocol.mav_client import connected_station
from tests.support.configs import client_vehicle


@pytest.fixture
def client_gcs(vehicle_factory, tmp_path):
    """A pymavlink ground station connected to a vehicle with the commander (no mission)."""
    yield from connected_station(vehicle_factory, lambda url: client_vehicle(url, tmp_path))
