"""The pytest plug-in (entry point ``pytest11``: ``companion``): vehicles on loopback for
a user's tests of their own scripts. See docs/user/testing_scripts.md.

Fixtures: ``sim`` (JSBSim in lockstep), ``bench`` (sensors replayed from a log),
``vehicle`` (whichever of the two the test asked for, else ``sim``), ``mavsdk_system`` (a
connected ``mavsdk`` System, with pytest-asyncio). Options:
``@pytest.mark.vehicle(airframe="c172p", wind=(0, 5, 0), ...)`` or an indirect parameter of
the fixture (``@pytest.mark.parametrize("sim", [{"turbulence": "light"}], indirect=True)``).
"""

from __future__ import annotations

import re
from collections.abc import AsyncIterator, Iterator
from contextlib import closing
from pathlib import Path
from typing import Any

import pytest

from companion.testing.bench import start_bench
from companion.testing.loopback import LoopbackVehicle, start_sim
from companion.testing.options import VehicleOptions

MARKER = "vehicle"


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        f"{MARKER}(**options): the options of the test's vehicle (airframe, speed, wind, "
        "turbulence, noise, seed, gps_outage, home, airborne, plan, duration, sim_args, "
        "sensor_log, arming_check); see companion.testing.options.VehicleOptions",
    )


def vehicle_options(request: pytest.FixtureRequest) -> VehicleOptions:
    """The marker's options (the closest one: function, then class, then module), then the
    fixture's indirect parameter, which wins."""
    marker = request.node.get_closest_marker(MARKER)
    return VehicleOptions.of(
        marker.kwargs if marker is not None else None, getattr(request, "param", None)
    )


def _folder(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory, kind: str
) -> Path:
    """A fresh folder per vehicle, under pytest's temporary directory (kept for the last
    three sessions, so a failed flight's truth, logs and output can be read after)."""
    name = re.sub(r"[^\w.-]", "_", request.node.name)[:40]
    return tmp_path_factory.mktemp(f"{kind}-{name}")


@pytest.fixture
def sim(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[LoopbackVehicle]:
    """``companion sim`` (lockstep unless ``speed`` says otherwise) on free loopback ports."""
    folder = _folder(request, tmp_path_factory, "sim")
    with closing(start_sim(folder, vehicle_options(request))) as vehicle:
        yield vehicle


@pytest.fixture
def bench(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[LoopbackVehicle]:
    """``companion run`` with sensors replayed from a log, no simulator."""
    folder = _folder(request, tmp_path_factory, "bench")
    with closing(start_bench(folder, vehicle_options(request))) as vehicle:
        yield vehicle


@pytest.fixture
def vehicle(request: pytest.FixtureRequest) -> LoopbackVehicle:
    """The test's vehicle: ``bench`` if the test uses it, else ``sim``."""
    kind = "bench" if "bench" in request.fixturenames else "sim"
    return request.getfixturevalue(kind)


@pytest.fixture
def pymavlink_url(vehicle: LoopbackVehicle) -> str:
    """``mavutil.mavlink_connection(pymavlink_url)`` reaches the test's vehicle."""
    return vehicle.pymavlink_url


@pytest.fixture
def mavsdk_url(vehicle: LoopbackVehicle) -> str:
    """``Mavsdk.add_any_connection(mavsdk_url)`` reaches the test's vehicle."""
    return vehicle.mavsdk_url


@pytest.fixture
def mavproxy_master(vehicle: LoopbackVehicle) -> str:
    """``mavproxy.py --master MASTER`` reaches the test's vehicle."""
    return vehicle.mavproxy_master


try:
    import pytest_asyncio

    HAS_PYTEST_ASYNCIO = True
except ImportError:  # the fixture needs pytest-asyncio (companion[testing] has it)
    HAS_PYTEST_ASYNCIO = False

if HAS_PYTEST_ASYNCIO:

    @pytest_asyncio.fixture
    async def mavsdk_system(vehicle: LoopbackVehicle) -> AsyncIterator[Any]:
        """A ``mavsdk`` System already connected to the test's vehicle (its autopilot)."""
        from mavsdk.asyncio import Configuration, Mavsdk
        from mavsdk.component_type import ComponentType

        config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
        async with Mavsdk(config) as mavsdk:
            await mavsdk.add_any_connection(vehicle.mavsdk_url)
            yield await mavsdk.first_autopilot(timeout_s=120.0)
