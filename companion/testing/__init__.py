"""Vehicles on loopback for tests of scripts (MAVSDK, pymavlink, MAVProxy) and a pytest
plug-in that gives them as fixtures (``pip install companion[testing]``; the plug-in is
``companion.testing.pytest_plugin``, registered as ``pytest11`` entry point ``companion``).

Ground-side code: nothing that flies imports it (an import-linter contract says so). It
starts the vehicle as a user would, ``python -m companion sim`` or ``run``, in a process
of its own, and talks to it only over MAVLink.
"""

from companion.testing.bench import start_bench
from companion.testing.loopback import LoopbackVehicle, start_sim
from companion.testing.options import VehicleOptions
from companion.testing.processes import free_udp_port, unique_namespace
from companion.testing.watcher import VehicleError

__all__ = [
    "LoopbackVehicle",
    "VehicleError",
    "VehicleOptions",
    "free_udp_port",
    "start_bench",
    "start_sim",
    "unique_namespace",
]
