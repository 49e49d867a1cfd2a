"""Shared fixtures: a real vehicle per test, each on its own bus namespace."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from tests.support.vehicle import Vehicle


@pytest.fixture
def vehicle_factory(tmp_path: Path) -> Iterator[Callable[..., Vehicle]]:
    """Start ``companion run`` on a config text; everything is stopped afterwards."""
    made: list[Vehicle] = []

    def make(config_text: str, namespace: str | None = None) -> Vehicle:
        sub = tmp_path / f"v{len(made)}"
        sub.mkdir()
        vehicle = Vehicle(config_text, sub, namespace).start()
        made.append(vehicle)
        return vehicle

    yield make
    for vehicle in made:
        vehicle.close()
