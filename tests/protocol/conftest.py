"""Fixtures shared by the protocol tests."""

from __future__ import annotations

import pytest

from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.support.configs import client_vehicle


@pytest.fixture
def client_gcs(vehicle_factory, tmp_path):
    """A pymavlink ground station connected to a vehicle with the commander (no mission)."""
    port = free_udp_port()
    vehicle_factory(client_vehicle(f"udpin://127.0.0.1:{port}", tmp_path))
    gcs = GroundStation(port)
    gcs.connect()
    yield gcs
    gcs.close()
